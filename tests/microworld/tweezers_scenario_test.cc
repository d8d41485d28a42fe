#include "microcobot/microworld/tweezers_scenario.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/core/rng.h"
#include "microcobot/ident/stats.h"

namespace mc::microworld {
namespace {

// The bead's excursion from the trap centre, y - y_trap (m), over [t0, t1).
std::vector<double> excursion(const TweezersRecord& r, double t0, double t1) {
  std::vector<double> out;
  for (std::size_t i = 0; i < r.t_s.size(); ++i)
    if (r.t_s[i] >= t0 && r.t_s[i] < t1) out.push_back(r.bead_y_m[i] - r.trap_y_m[i]);
  return out;
}

TEST(TweezersScenario, RecordsAtTheLoopRateWithTheForceOfTheSpringModel) {
  const OpticalTrapParams p;
  TweezersOptions o;
  o.duration_s = 0.2;
  const TweezersRecord r = simulate_tweezers(p, TweezersScenario::kBrownian, o);
  ASSERT_EQ(r.t_s.size(), 2000u);  // 0.2 s at 10 kHz
  ASSERT_EQ(r.bead_y_m.size(), r.t_s.size());
  ASSERT_EQ(r.hand_force_N.size(), r.t_s.size());
  EXPECT_EQ(r.contact_time_s, -1.0);
  for (std::size_t i = 0; i < r.t_s.size(); ++i) {
    EXPECT_NEAR(r.t_s[i], static_cast<double>(i) * 1e-4, 1e-12);
    EXPECT_EQ(r.trap_y_m[i], 0.0);  // Brownian only: the probe is held still
    // Measured force k (y - y_trap) (Fig. 3.3), and the hand force proportional to it.
    EXPECT_DOUBLE_EQ(r.force_y_N[i], p.trap_stiffness_N_per_m * (r.bead_y_m[i] - r.trap_y_m[i]));
    EXPECT_DOUBLE_EQ(r.hand_force_N[i], o.force_scale * r.force_y_N[i]);
  }
}

TEST(TweezersScenario, TrapStiffnessFromTheBeadVarianceAndTheCornerFromItsPsd) {
  // Two trap stiffnesses: equipartition k = k_B T / var(y - y_trap) within 10 %, and the PSD
  // corner within 5 % of k / (2 pi gamma) (the acceptance bound).
  for (double k : {1.0e-5, 4.0e-5}) {
    OpticalTrapParams p;
    p.trap_stiffness_N_per_m = k;
    TweezersOptions o;
    o.duration_s = 8.0;
    const TweezersRecord r = simulate_tweezers(p, TweezersScenario::kBrownian, o);
    const std::vector<double> x = excursion(r, 0.0, o.duration_s);
    const double var = ident::stddev(x) * ident::stddev(x);
    const double k_est = OpticalTrap::kBoltzmann * p.temperature_K / var;
    EXPECT_NEAR(k_est / k, 1.0, 0.10) << k;
    EXPECT_NEAR(ident::mean(x), 0.0, 0.1 * std::sqrt(var)) << k;
    const OpticalTrap trap(p);
    EXPECT_NEAR(fit_corner_frequency(x, o.record_rate_Hz) / trap.corner_frequency_Hz(), 1.0, 0.05) << k;
  }
}

TEST(TweezersScenario, BrownianForceAtTheHandIsGaussianAtTheDocumentedScale) {
  const OpticalTrapParams p;
  TweezersOptions o;
  o.duration_s = 8.0;
  const TweezersRecord r = simulate_tweezers(p, TweezersScenario::kBrownian, o);
  // rms hand force = scale * sqrt(k k_B T): ~0.2 pN at the bead -> ~0.04 N at the hand.
  const double expected_rms =
      o.force_scale * std::sqrt(p.trap_stiffness_N_per_m * OpticalTrap::kBoltzmann * p.temperature_K);
  EXPECT_NEAR(ident::stddev(r.hand_force_N) / expected_rms, 1.0, 0.1);
  EXPECT_NEAR(ident::kurtosis(r.hand_force_N), 0.0, 0.3);  // excess kurtosis of a Gaussian
  EXPECT_NEAR(ident::skewness(r.hand_force_N), 0.0, 0.2);
}

TEST(TweezersScenario, ContactAtTheGapOverTheSpeedThenAForcePeakAndRelease) {
  const OpticalTrapParams p;
  TweezersOptions o;
  o.duration_s = 1.2;
  const TweezersRecord r = simulate_tweezers(p, TweezersScenario::kContact, o);
  // The trap moves at 4 um/s from a 2 um gap: contact after ~0.5 s (Brownian excursions of
  // sqrt(k_B T / k) = 20 nm shift it by a few ms).
  const double t_gap = o.initial_gap_m / o.approach_speed_m_s;
  EXPECT_NEAR(r.contact_time_s, t_gap, 0.02);
  // Free approach: the trap moves at the commanded speed and the force stays Brownian.
  const double brownian = std::sqrt(p.trap_stiffness_N_per_m * OpticalTrap::kBoltzmann * p.temperature_K);
  for (std::size_t i = 0; i < r.t_s.size(); ++i) {
    if (r.t_s[i] >= r.contact_time_s) break;
    EXPECT_NEAR(r.trap_y_m[i], o.approach_speed_m_s * r.t_s[i], 1e-12);
    EXPECT_LT(std::abs(r.force_y_N[i]), 6.0 * brownian) << r.t_s[i];
  }
  // Peak: the stuck bead holds the probe back while the trap goes on for retract_after_s, so
  // the bead lags the trap by ~v * t_r (the contact spring is 40x stiffer than the trap):
  // force k (y - y_trap) ~ -k v t_r = -6 pN, at the operator's turn-around.
  const auto peak = std::min_element(r.force_y_N.begin(), r.force_y_N.end());
  const double t_peak = r.t_s[static_cast<std::size_t>(peak - r.force_y_N.begin())];
  EXPECT_GT(t_peak, r.contact_time_s);
  EXPECT_NEAR(t_peak, r.contact_time_s + o.retract_after_s, 0.02);
  const double expected_peak = -p.trap_stiffness_N_per_m * o.approach_speed_m_s * o.retract_after_s;
  EXPECT_NEAR(*peak / expected_peak, 1.0, 0.15);
  EXPECT_LT(*peak, -10.0 * brownian);
  // The retraction runs at the approach speed, so the trap is back at the contact point
  // retract_after_s after the turn-around; from then on the force is Brownian again.
  const double t_free = r.contact_time_s + 2.0 * o.retract_after_s + 0.05;
  ASSERT_LT(t_free, o.duration_s - 0.1);
  for (std::size_t i = 0; i < r.t_s.size(); ++i) {
    if (r.t_s[i] < t_free) continue;
    EXPECT_LT(std::abs(r.force_y_N[i]), 6.0 * brownian) << r.t_s[i];
  }
}

TEST(TweezersScenario, SeededRunsRepeatAndDifferentSeedsDiffer) {
  const OpticalTrapParams p;
  TweezersOptions o;
  o.duration_s = 0.05;
  const TweezersRecord a = simulate_tweezers(p, TweezersScenario::kBrownian, o);
  const TweezersRecord b = simulate_tweezers(p, TweezersScenario::kBrownian, o);
  EXPECT_EQ(a.bead_y_m, b.bead_y_m);
  o.seed = 4;
  const TweezersRecord c = simulate_tweezers(p, TweezersScenario::kBrownian, o);
  EXPECT_NE(a.bead_y_m, c.bead_y_m);
}

TEST(TweezersScenario, CornerFitOfAnExactSampledOrnsteinUhlenbeckProcess) {
  // x[k+1] = a x[k] + e[k] is an OU process sampled at T with a = exp(-2 pi f_c T).
  const double fs = 1.0e4, fc = 150.0;
  const double a = std::exp(-2.0 * std::numbers::pi * fc / fs);
  Rng rng(9);
  std::vector<double> x(1u << 17);
  for (std::size_t k = 1; k < x.size(); ++k) x[k] = a * x[k - 1] + rng.normal();
  EXPECT_NEAR(fit_corner_frequency(x, fs) / fc, 1.0, 0.03);
  // A PSD that rises with frequency (differenced white noise) is no Lorentzian decay.
  std::vector<double> blue(1u << 14);
  double prev = rng.normal();
  for (double& v : blue) {
    const double e = rng.normal();
    v = e - prev;
    prev = e;
  }
  EXPECT_THROW(fit_corner_frequency(blue, fs), ComputationFailed);
}

TEST(TweezersScenario, RejectsBadScenariosAndOptions) {
  EXPECT_EQ(parse_scenario("brownian"), TweezersScenario::kBrownian);
  EXPECT_EQ(parse_scenario("contact"), TweezersScenario::kContact);
  EXPECT_THROW(parse_scenario("Brownian"), UsageError);
  TweezersOptions o;
  o.duration_s = 0.0;
  EXPECT_THROW(simulate_tweezers(OpticalTrapParams{}, TweezersScenario::kBrownian, o), InvalidParams);
  o = {};
  o.record_rate_Hz = 1.0e6;  // faster than the 1e-5 s integration step
  EXPECT_THROW(simulate_tweezers(OpticalTrapParams{}, TweezersScenario::kBrownian, o), InvalidParams);
}

}  // namespace
}  // namespace mc::microworld
