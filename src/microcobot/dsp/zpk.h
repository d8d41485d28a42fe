#pragma once
/// @file
/// Zero-pole-gain systems and their conversion to second-order sections with scipy's
/// 'nearest' pairing (scipy.signal.zpk2sos), so that designed filters match scipy's
/// section by section.

#include <complex>
#include <vector>

#include "microcobot/dsp/sos.h"

namespace mc::dsp {

/// H = k * prod(x - z_i) / prod(x - p_i), x = s (analog) or z (digital). Complex roots come
/// in conjugate pairs.
struct Zpk {
  std::vector<std::complex<double>> z;
  std::vector<std::complex<double>> p;
  double k = 1.0;
};

/// Second-order sections of a digital zpk system, exactly as scipy.signal.zpk2sos(z, p, k)
/// with pairing='nearest' (scipy 1.10): poles nearest the unit circle go last, each paired
/// with its nearest zeros; the gain goes into the first section.
/// Throws InvalidParams if a complex root lacks its conjugate.
Sos zpk2sos(const Zpk& zpk);

/// The bilinear transform of an analog zpk system with sample rate fs (scipy.signal.bilinear_zpk):
/// x -> (2fs + x)/(2fs - x); zeros at infinity go to z = -1.
Zpk bilinear_zpk(const Zpk& analog, double fs);

/// Coefficients of prod(x - r_i), highest power first, real parts (numpy.poly).
std::vector<double> poly_from_roots(const std::vector<std::complex<double>>& roots);

}  // namespace mc::dsp
