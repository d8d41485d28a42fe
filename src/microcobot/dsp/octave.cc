#include "microcobot/dsp/octave.h"

#include <array>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::dsp {

std::vector<double> third_octave_centres(double fmin_Hz, double fmax_Hz) {
  require(std::isfinite(fmin_Hz) && fmin_Hz > 0, "fmin_Hz", "must be > 0", fmin_Hz);
  require(std::isfinite(fmax_Hz) && fmax_Hz > fmin_Hz, "fmax_Hz", "must be > fmin_Hz", fmax_Hz);
  // Small slack so that nominal edges (e.g. exactly 100 Hz) count as inside.
  const int k0 = static_cast<int>(std::ceil(10.0 * std::log10(fmin_Hz / 1000.0) - 1e-9));
  const int k1 = static_cast<int>(std::floor(10.0 * std::log10(fmax_Hz / 1000.0) + 1e-9));
  std::vector<double> out;
  for (int k = k0; k <= k1; ++k) out.push_back(1000.0 * std::pow(10.0, k / 10.0));
  return out;
}

double third_octave_nominal(double fc_Hz) {
  require(std::isfinite(fc_Hz) && fc_Hz > 0, "fc_Hz", "must be > 0", fc_Hz);
  static constexpr std::array<double, 10> kR10 = {1.0, 1.25, 1.6, 2.0, 2.5, 3.15, 4.0, 5.0, 6.3, 8.0};
  const auto k = static_cast<long>(std::lround(10.0 * std::log10(fc_Hz)));  // band index re 1 Hz
  const long decade = k >= 0 ? k / 10 : -((-k + 9) / 10);                   // floor(k / 10)
  return kR10[static_cast<std::size_t>(k - 10 * decade)] * std::pow(10.0, static_cast<double>(decade));
}

OctaveBands third_octave_average(std::span<const double> f_Hz, std::span<const std::complex<double>> h,
                                 double fmin_Hz, double fmax_Hz) {
  require(f_Hz.size() == h.size(), "h", "must have one value per frequency", static_cast<double>(h.size()));
  OctaveBands out;
  const double half = std::pow(10.0, 1.0 / 20.0);
  for (double fc : third_octave_centres(fmin_Hz, fmax_Hz)) {
    const double lo = fc / half, hi = fc * half;
    double acc = 0.0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < f_Hz.size(); ++i) {
      if (f_Hz[i] >= lo && f_Hz[i] < hi) {
        acc += std::norm(h[i]);
        ++n;
      }
    }
    if (n == 0 || !(acc > 0)) continue;
    out.fc_Hz.push_back(fc);
    out.mag_dB.push_back(10.0 * std::log10(acc / static_cast<double>(n)));
    out.points.push_back(n);
  }
  return out;
}

}  // namespace mc::dsp
