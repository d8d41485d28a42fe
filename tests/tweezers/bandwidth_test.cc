// Bandwidth identification (section 4.5.2): PRBS at 10 kHz, H1, mode / antiresonance / flat band.
#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/tweezers/bandwidth.h"

namespace mc::tweezers {
namespace {

TEST(FrfFeatures, ReadsAKnownResonanceAndNotch) {
  // |H| = |(1 - (f/fz)^2 + j..)/(1 - (f/fp)^2 + j 2 zeta f/fp)| on a 1 Hz grid: peak at fp
  // sqrt(1 - 2 zeta^2), notch at fz, flat band from the analytic +-3 dB spread.
  const double fp = 200, fz = 500, zp = 0.05, zz = 0.01;
  std::vector<double> f, m;
  for (double x = 1; x < 3000; x += 1) {
    const std::complex<double> num(1 - x * x / (fz * fz), 2 * zz * x / fz),
        den(1 - x * x / (fp * fp), 2 * zp * x / fp);
    f.push_back(x);
    m.push_back(std::abs(num / den));
  }
  BandwidthIdentParams p;
  const auto ft = frf_features(f, m, p);
  EXPECT_NEAR(ft.mode_Hz, fp * std::sqrt(1 - 2 * zp * zp), 1.0);
  EXPECT_NEAR(ft.antiresonance_Hz, fz, 1.0);
  // Spread over [20, fb] reaches 6 dB where |H| = 2 (the low end is ~1).
  double fb = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (f[i] >= 20 && 20 * std::log10(m[i] / m[19]) > 6.0) {
      fb = f[i - 1];
      break;
    }
  }
  EXPECT_NEAR(ft.bandwidth_Hz, fb, 1.5);
  EXPECT_LT(ft.bandwidth_Hz, ft.mode_Hz);
  // A tighter tolerance gives a narrower band.
  p.flatness_dB = 1.0;
  EXPECT_LT(frf_features(f, m, p).bandwidth_Hz, ft.bandwidth_Hz);
  // A featureless FRF has no mode.
  std::vector<double> flat(f.size(), 1.0);
  EXPECT_THROW(frf_features(f, flat, BandwidthIdentParams{}), ComputationFailed);
}

TEST(BandwidthIdent, ReproducesFigure425) {
  const auto r = identify_bandwidth(TeleTweezParams{}, BandwidthIdentParams{});
  EXPECT_NEAR(r.features.mode_Hz, 150, 10);
  EXPECT_NEAR(r.features.antiresonance_Hz, 390, 20);
  EXPECT_GE(r.features.bandwidth_Hz, 100);
  EXPECT_LT(r.features.bandwidth_Hz, r.features.mode_Hz);
  // The H1 estimate agrees with the analytic FRF where the coherence is high.
  int compared = 0;
  for (std::size_t i = 0; i < r.f_Hz.size(); ++i) {
    if (r.f_Hz[i] < 20 || r.f_Hz[i] > 1000 || r.coherence[i] < 0.95) continue;
    ++compared;
    EXPECT_NEAR(20 * std::log10(r.magnitude[i] / r.model_magnitude[i]), 0.0, 1.0) << r.f_Hz[i];
  }
  EXPECT_GT(compared, 500);
  EXPECT_EQ(r.t_s.size(), r.accel_m_s2.size());
  RecordProperty("mode_Hz", std::to_string(r.features.mode_Hz));
  std::printf("mode %.1f Hz, antiresonance %.1f Hz, bandwidth %.1f Hz\n", r.features.mode_Hz,
              r.features.antiresonance_Hz, r.features.bandwidth_Hz);
}

TEST(BandwidthIdent, StifferLeverRaisesTheMode) {
  TeleTweezParams stiff;
  stiff.lever_stiffness_N_per_m *= 2;
  BandwidthIdentParams p;
  p.duration_s = 4.0;
  const auto a = identify_bandwidth(TeleTweezParams{}, p);
  const auto b = identify_bandwidth(stiff, p);
  EXPECT_GT(b.features.mode_Hz, 1.1 * a.features.mode_Hz);
  // The antiresonance belongs to the tip (k_cl / m_cl), not to the lever.
  EXPECT_NEAR(b.features.antiresonance_Hz, a.features.antiresonance_Hz, 10);
}

TEST(BandwidthIdent, RejectsBadParams) {
  BandwidthIdentParams p;
  p.nperseg = 1 << 20;
  EXPECT_THROW(identify_bandwidth(TeleTweezParams{}, p), InvalidParams);
}

}  // namespace
}  // namespace mc::tweezers
