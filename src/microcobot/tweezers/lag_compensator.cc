#include "microcobot/tweezers/lag_compensator.h"

#include <cmath>
#include <complex>
#include <numbers>

#include "microcobot/core/error.h"
#include "microcobot/dsp/lti.h"

namespace mc::tweezers {

namespace {
dsp::Sos design(double pole_Hz, double zero_Hz, double rate_Hz) {
  require_positive(rate_Hz, "rate_Hz");
  require_positive(pole_Hz, "pole_Hz");
  require(zero_Hz > pole_Hz, "zero_Hz", "must be above pole_Hz (a lag)", zero_Hz);
  require(zero_Hz < rate_Hz / 2, "zero_Hz", "must be below the Nyquist frequency", zero_Hz);
  const double wz = 2 * std::numbers::pi * zero_Hz, wp = 2 * std::numbers::pi * pole_Hz;
  const dsp::TransferFunction analog({1.0 / wz, 1.0}, {1.0 / wp, 1.0});
  const dsp::TransferFunction d = dsp::c2d(analog, 1.0 / rate_Hz, dsp::Discretization::kTustin).normalized();
  // First order: num = [b0, b1], den = [1, a1].
  const auto& n = d.num();
  const auto& a = d.den();
  dsp::Biquad q;
  q.b0 = n.size() == 2 ? n[0] : 0.0;
  q.b1 = n.back();
  q.a1 = a.size() == 2 ? a[1] : 0.0;
  return {q};
}
}  // namespace

LagCompensator::LagCompensator(double pole_Hz, double zero_Hz, double rate_Hz)
    : pole_Hz_(pole_Hz), zero_Hz_(zero_Hz), rate_Hz_(rate_Hz), filter_(design(pole_Hz, zero_Hz, rate_Hz)) {}

namespace {
std::complex<double> response(const dsp::Biquad& q, double f_Hz, double rate_Hz) {
  const std::complex<double> zi = std::exp(std::complex<double>(0.0, -2 * std::numbers::pi * f_Hz / rate_Hz));
  return (q.b0 + q.b1 * zi + q.b2 * zi * zi) / (1.0 + q.a1 * zi + q.a2 * zi * zi);
}
}  // namespace

double LagCompensator::magnitude(double f_Hz) const {
  return std::abs(response(filter_.sections()[0], f_Hz, rate_Hz_));
}

double LagCompensator::phase(double f_Hz) const {
  return std::arg(response(filter_.sections()[0], f_Hz, rate_Hz_));
}

}  // namespace mc::tweezers
