#pragma once
/// @file
/// The mechanical amplifier of the piezo-stack brake (option 3.1, thesis appendix A, eq. A.1-A.11,
/// Table 4.5): a rhombus of rigid links around the stack turns its axial contraction dL into a
/// transverse expansion 2 da.

namespace mc::tweezers {

struct AmplifierResult {
  double transverse_expansion_m = 0;  ///< 2 da
  double ratio = 0;                   ///< 2 da / dL
};

/// Eq. A.8: da = sqrt(a^2 + L_e dL / 2 - dL^2 / 4) - a with L_e = L + 2e (eq. A.7), where L is the
/// stack length, dL its stroke, e the connection length between stack and amplifier poles and
/// a the half-height of the amplifier (Table 4.5 lists a as radius + 2 mm). The segment c stays
/// rigid (eq. A.2-A.3). Throws InvalidParams unless 0 < dL < L_e and lengths are positive.
AmplifierResult amplifier_expansion(double length_m, double stroke_m, double e_m, double a_m);

}  // namespace mc::tweezers
