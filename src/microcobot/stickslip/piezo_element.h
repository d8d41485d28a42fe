#pragma once
/// @file
/// The piezoelectric element (PE): two vibration modes sharing the mass M_p (thesis eq. 2.1-2.3),
/// driven by the hysteretic "equivalent voltage" H(U) through a linear part of unit static gain
/// (eq. 2.5-2.7 as read in docs/errata.md, "Eq. 2.5") and loaded by the friction force -F_f.
///
///   M_p x1a'' + D_pa x1a' + K_pa x1a = K_act1 g H(U) F_h' - F_f      (2.1, normalised as 2.5/2.6)
///   M_p x1b'' + D_pb x1b' + K_pb x1b = K_act2 g H(U) F_h' - F_f      (2.2)
///   x1 = x1a + x1b                                                   (2.3)
/// With K_act1/K_pa = phi g and K_act2/K_pb = (1 - phi) g, the static displacement is
/// x1 = g H(U) - (1/K_pa + 1/K_pb) F_f (eq. 2.4): `gain_fraction_a` = phi is the split of the static
/// gain between the modes, `static_gain_m_V` = g the normalised gain (F_h of eq. 2.6 makes the
/// linear part's gain 1; g converts the PI output in volts to metres).

#include <array>

namespace mc::stickslip {

struct PiezoParams {
  double mass_kg = 0.00075;         ///< M_p, Table 2.8
  double damping_a_N_s_m = 25.86;   ///< D_pa, Table 2.8 (N s/m: docs/errata.md, "Table 2.8 units")
  double stiffness_a_N_m = 1.23e8;  ///< K_pa, Table 2.8 (N/m, the same erratum): 64.4 kHz
  double damping_b_N_s_m = 82.17;   ///< D_pb, Table 2.8
  double stiffness_b_N_m = 4.24e8;  ///< K_pb, Table 2.8: 119.7 kHz
  double static_gain_m_V =
      15e-9;  ///< g: PE stroke per equivalent volt (erratum 7 in docs/errata.md: ~1.5 um at 100 V)
  double gain_fraction_a =
      0.7;  ///< phi = (K_act1/K_pa) / (K_act1/K_pa + K_act2/K_pb), erratum 7 (docs/errata.md)

  template <class V>
  void visit(V& v) {
    v("mass_kg", mass_kg);
    v("damping_a_N_s_m", damping_a_N_s_m);
    v("stiffness_a_N_m", stiffness_a_N_m);
    v("damping_b_N_s_m", damping_b_N_s_m);
    v("stiffness_b_N_m", stiffness_b_N_m);
    v("static_gain_m_V", static_gain_m_V);
    v("gain_fraction_a", gain_fraction_a);
  }
  void validate() const;

  /// K_act1, K_act2 [N/V] implied by g and phi (eq. 2.4).
  double k_act_a() const { return gain_fraction_a * static_gain_m_V * stiffness_a_N_m; }
  double k_act_b() const { return (1.0 - gain_fraction_a) * static_gain_m_V * stiffness_b_N_m; }
  /// Undamped natural frequencies sqrt(K/M_p) / 2pi [Hz].
  double natural_frequency_a_Hz() const;
  double natural_frequency_b_Hz() const;
};

/// Exact discretisation of one damped mode x'' = -(K/M) x - (D/M) x' + f/M over a step h, with a
/// first-order hold on f (exact for piecewise-linear forcing):
///   [x; v]_{k+1} = Phi [x; v]_k + G0 f_k + G1 (f_{k+1} - f_k).
struct ModeDiscretization {
  std::array<double, 4> phi{};  ///< row-major 2x2
  std::array<double, 2> g0{};
  std::array<double, 2> g1{};

  /// The matrices from exp(A h) of the augmented system [x, v, f, fdot], computed in the mode's
  /// own units (every entry of order omega h) by scaling and squaring a Taylor series: accurate
  /// to rounding for any h (the raw system's entries span 1e-3 to 1e11, which cost a generic
  /// matrix exponential ~1e-6). Used for a step of any length inside the loop too (a sub-step
  /// split at a drive corner): never allocates.
  static ModeDiscretization make(double mass, double damping, double stiffness, double h) noexcept;

  /// One exact step with the force split as f = drive - reaction, the reaction held over the step:
  /// the reaction (the friction of the previous sub-step, the latest value to arrive) enters last.
  void step_with_reaction(double& x, double& v, double drive0, double drive1,
                          double reaction) const noexcept {
    const double xn = phi[0] * x + phi[1] * v + g0[0] * drive0 + g1[0] * (drive1 - drive0) - g0[0] * reaction;
    const double vn = phi[2] * x + phi[3] * v + g0[1] * drive0 + g1[1] * (drive1 - drive0) - g0[1] * reaction;
    x = xn;
    v = vn;
  }

  /// One exact step. Never allocates.
  void step(double& x, double& v, double f0, double f1) const noexcept {
    const double xn = phi[0] * x + phi[1] * v + g0[0] * f0 + g1[0] * (f1 - f0);
    const double vn = phi[2] * x + phi[3] * v + g0[1] * f0 + g1[1] * (f1 - f0);
    x = xn;
    v = vn;
  }
};

}  // namespace mc::stickslip
