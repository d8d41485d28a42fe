#include "microcobot/live/contact_rumble.h"

#include <algorithm>
#include <cmath>

#include "microcobot/dsp/butterworth.h"

namespace mc::live {

namespace {
dsp::SosFilter high_band(double crossover_Hz, double rate_Hz) {
  return dsp::SosFilter(dsp::linkwitz_riley(4, crossover_Hz, rate_Hz, dsp::FilterType::kHighPass));
}
}  // namespace

ContactRumble::ContactRumble(double crossover_Hz, double rate_Hz, double full_scale_N)
    : high_{high_band(crossover_Hz, rate_Hz), high_band(crossover_Hz, rate_Hz),
            high_band(crossover_Hz, rate_Hz)},
      full_scale_N_(full_scale_N) {}

void ContactRumble::add(double fx_N, double fy_N, double fz_N) noexcept {
  // A sample without a force (a driver without the sensor) must not leave NaN in the filters.
  auto finite = [](double v) { return std::isfinite(v) ? v : 0.0; };
  const double hx = high_[0].process(finite(fx_N)), hy = high_[1].process(finite(fy_N)),
               hz = high_[2].process(finite(fz_N));
  sum_ += hx * hx + hy * hy + hz * hz;
  ++n_;
}

double ContactRumble::take() noexcept {
  const double rms = n_ ? std::sqrt(sum_ / static_cast<double>(n_)) : 0.0;
  sum_ = 0.0;
  n_ = 0;
  return std::isfinite(rms) ? std::min(1.0, rms / full_scale_N_) : 0.0;
}

}  // namespace mc::live
