#include "microcobot/dsp/sine_dwell.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/dsp/lti.h"
#include "microcobot/dsp/signals.h"

namespace mc::dsp {
namespace {

TEST(SineDwell, MeasuresEq36AtResonance) {
  const TransferFunction g({250.0, 6.406e5}, {1.0, 2135.0, 4.559e6});
  const double fs = 10000.0, f = 337.3;  // not an integer number of samples per period
  const std::size_t n = 5000;
  const auto u = sine(n, f, fs, 0.8);
  std::vector<double> t(n);
  for (std::size_t k = 0; k < n; ++k) t[k] = static_cast<double>(k) / fs;
  auto y = lsim(g, u, t, true);
  const auto noise = white_noise(n, 0.002, 1);
  for (std::size_t k = 0; k < n; ++k) y[k] += noise[k];
  const auto r = sine_dwell(u, y, f, fs, 2000);  // 0.2 s settle >> 1/1067 s time constant
  // lsim joins the samples linearly: the plant sees a fundamental scaled by sinc^2(f/fs)
  // (zero phase), so that is the response the measurement must find.
  const double x = std::numbers::pi * f / fs;
  const auto want = g.response(2 * std::numbers::pi * f) * std::pow(std::sin(x) / x, 2);
  EXPECT_NEAR(r.magnitude, std::abs(want), 5e-4 * std::abs(want));
  EXPECT_NEAR(r.phase_rad, std::arg(want), 5e-4);
  EXPECT_NEAR(r.input_amplitude, 0.8, 1e-12);
  EXPECT_NEAR(r.output_residual_rms, 0.002, 0.0003);
}

TEST(SineDwell, RejectsTooShortAndNoInput) {
  std::vector<double> u(50, 0.0), y(50, 0.0);
  EXPECT_THROW(sine_dwell(u, y, 10.0, 1000.0), InvalidParams);   // 50 samples < 1 period of 100
  EXPECT_THROW(sine_dwell(u, y, 100.0, 1000.0), InvalidParams);  // u has no sine
}

}  // namespace
}  // namespace mc::dsp
