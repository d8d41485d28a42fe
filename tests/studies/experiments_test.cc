// The thesis's chapter-2 experiments on the default model (§2.5, Fig. 2.10-2.17), with their
// numeric checks, and the fixed-step integrator's error against the odeint reference.
#include "microcobot/studies/experiments.h"

#include <cmath>

#include <gtest/gtest.h>

#include "microcobot/stickslip/reference_solver.h"

namespace mc::studies {
namespace {

TEST(Experiments, PeStepPeaks) {
  const auto r = run_pe_step(stickslip::StickSlipParams{});
  ASSERT_EQ(r.peaks_Hz.size(), 2u);
  EXPECT_NEAR(r.peaks_Hz[0], 64e3, 2e3);
  EXPECT_NEAR(r.peaks_Hz[1], 118e3, 4e3);
}

TEST(Experiments, ActuatorStepPeaks) {
  const auto r = run_actuator_step(stickslip::StickSlipParams{});
  ASSERT_EQ(r.peaks_Hz.size(), 2u);
  EXPECT_NEAR(r.peaks_Hz[0], 595.0, 15.0);
  EXPECT_NEAR(r.peaks_Hz[1], 1633.0, 40.0);
}

TEST(Experiments, ScanningDoesNotStep) {
  for (const auto& c : run_scanning(stickslip::StickSlipParams{})) {
    EXPECT_FALSE(c.stepping);
    EXPECT_LT(std::abs(c.net_displacement_m), 0.02 * c.stroke_m)
        << c.frequency_Hz << " Hz " << to_string(c.direction);
    // The slider does follow the PE within a period (scanning, not standing still).
    double lo = 1, hi = -1;
    for (double x : c.trajectory.x2_m) {
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
    EXPECT_GT(hi - lo, 0.5 * c.stroke_m);
  }
}

TEST(Experiments, SteppingDirectionSpeedAndAsymmetry) {
  const auto cases = run_stepping(stickslip::StickSlipParams{});
  ASSERT_EQ(cases.size(), 12u);
  auto find = [&](double a, double f, stickslip::Direction d) {
    for (const auto& c : cases) {
      if (c.amplitude_V == a && c.frequency_Hz == f && c.direction == d) return c;
    }
    ADD_FAILURE();
    return SawtoothCase{};
  };
  for (double f : {50.0, 100.0, 500.0}) {
    for (stickslip::Direction d : {stickslip::Direction::kForward, stickslip::Direction::kBackward}) {
      const double sign = d == stickslip::Direction::kForward ? 1.0 : -1.0;
      const auto c40 = find(40, f, d), c60 = find(60, f, d);
      EXPECT_TRUE(c40.stepping) << f << " Hz " << to_string(d);
      EXPECT_GT(sign * c40.velocity_m_s, 0.0);
      EXPECT_GT(sign * c60.velocity_m_s, sign * c40.velocity_m_s);  // larger speed at 60 V
    }
    for (double a : {40.0, 60.0}) {
      const double vf = find(a, f, stickslip::Direction::kForward).velocity_m_s;
      const double vb = -find(a, f, stickslip::Direction::kBackward).velocity_m_s;
      EXPECT_GT(std::abs(vf - vb), 0.01 * std::max(vf, vb)) << a << " V " << f << " Hz";  // asymmetry
    }
  }
}

TEST(Experiments, ThresholdNear40V) {
  const auto t = run_threshold(stickslip::StickSlipParams{});
  EXPECT_NEAR(t.forward_V, 40.0, 5.0);
  EXPECT_NEAR(t.backward_V, 40.0, 5.0);
}

TEST(Experiments, HysteresisLoopsAreOpenAndRateDependent) {
  const auto loops = run_hysteresis(stickslip::StickSlipParams{});
  ASSERT_EQ(loops.size(), 8u);
  for (const auto& l : loops) {
    EXPECT_GT(std::abs(l.area_V_m), 0.0);
    EXPECT_GT(l.range_m, 0.0);
  }
  // 50 Hz: quasi-static, the range follows the PE's gain; at 595 Hz (contact mode) the loop
  // is much wider relative to its amplitude: rate dependence from the dynamics (§2.4.1.1).
  const double quasi = std::abs(loops[0].area_V_m) / (loops[0].amplitude_V * loops[0].range_m);
  const double resonant = std::abs(loops[4].area_V_m) / (loops[4].amplitude_V * loops[4].range_m);
  EXPECT_GT(resonant, 2.0 * quasi);
  EXPECT_NEAR(loops[0].range_m, stickslip::StickSlipParams{}.pe.static_gain_m_V * 40.0, 0.3 * 600e-9);
}

TEST(Experiments, PsdDominatedByTheDriveFrequency) {
  const auto cases = run_psd(stickslip::StickSlipParams{});
  ASSERT_EQ(cases.size(), 2u);
  EXPECT_NEAR(cases[0].dominant_peak_Hz, 500.0, 10.0);
  EXPECT_NEAR(cases[1].dominant_peak_Hz, 50.0, 10.0);
}

TEST(Integrator, FixedStepWithinOnePercentOfReference) {
  // Acceptance: slider RMS error < 1% of its range at the default step.
  const stickslip::StickSlipParams p;
  const stickslip::ActuatorModel m(p);
  struct Case {
    double a, f;
    stickslip::Direction d;
    double duration;
  };
  for (const Case c : {Case{20, 500, stickslip::Direction::kForward, 0.01},
                       Case{40, 50, stickslip::Direction::kBackward, 0.06},
                       Case{60, 500, stickslip::Direction::kForward, 0.01},
                       Case{60, 100, stickslip::Direction::kBackward, 0.03}}) {
    const stickslip::Waveform w =
        stickslip::make_waveform(stickslip::WaveKind::kSawtooth, c.a, c.f, c.d, p.drive);
    const stickslip::Trajectory fixed = simulate(m, w, c.duration);
    stickslip::ReferenceOptions o;
    o.sample_dt_s = m.dt_s();
    const stickslip::Trajectory ref = stickslip::simulate_reference(p, w, c.duration, o);
    EXPECT_LT(stickslip::relative_rms_error(fixed, ref), 0.01) << c.a << " V " << c.f << " Hz";
  }
}

}  // namespace
}  // namespace mc::studies
