// Velocity control of thesis §2.7 (Fig. 2.18-2.19): 100 um/s forward and backward.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "control_fixture.h"
#include "microcobot/core/error.h"
#include "microcobot/motion/closed_loop.h"
#include "support/counting_allocator.h"

namespace mc::motion {
// The file's own namespace: its helpers keep their names beside the other test files of the
// module in a unity build (MC_UNITY_TESTS).
namespace velocity_control_test {
namespace {

const PositionSensorParams kSensor{};  // 0.1 nm resolution, 1 nm RMS noise

// The model steps intermittently at the loop's operating points (bursts of the per-period
// velocity at a constant amplitude), and which sensor-noise stream meets a burst, and when, is
// chaotic: the loops are judged over several noise streams, by the median where a figure is
// compared, every stream where a goal is asserted.
constexpr int kSeeds = 7;

VelocityRun run_seed(VelocityMode mode, double ref, double duration_s, int seed) {
  PositionSensorParams sensor = kSensor;
  sensor.seed = seed;
  return run_velocity(test::model(), mode == VelocityMode::kModelBased ? &test::step_map() : nullptr,
                      VelocityControlParams{}, mode, ref, duration_s, sensor);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

TEST(VelocityControl, ModelBasedPidReaches100umPerSecondBothWaysWithin2Percent) {
  for (double ref : {100e-6, -100e-6}) {
    std::vector<double> settling;
    for (int seed = 1; seed <= kSeeds; ++seed) {
      const auto run = run_seed(VelocityMode::kModelBased, ref, 0.3, seed);
      const auto& m = run.metrics;
      EXPECT_LT(std::abs(m.steady_state_error_rel), 0.02) << "ref " << ref << " seed " << seed;  // goal
      EXPECT_TRUE(m.settled) << seed;
      EXPECT_LT(m.ripple_m_s, 0.1 * std::abs(ref)) << seed;
      EXPECT_GT(m.mean_velocity_m_s * ref, 0.0);    // the right direction
      EXPECT_LT(m.max_excursion_rel, 0.3) << seed;  // bursts, not a loss of control
      settling.push_back(m.settling_time_s);
    }
    EXPECT_LT(median(settling), 0.1) << "ref " << ref;
  }
}

TEST(VelocityControl, SettlingIsTheLoopsConvergenceAndLaterBurstsAreCounted) {
  // A made-up record: on the reference from 10 periods on, one 3-period burst at +40 % later.
  VelocityRun r = run_seed(VelocityMode::kModelBased, 100e-6, 0.1, 1);
  ASSERT_EQ(r.v_true_m_s.size(), 100u);
  for (std::size_t i = 0; i < r.v_true_m_s.size(); ++i) r.v_true_m_s[i] = i < 10 ? 0.0 : 100e-6;
  for (std::size_t i = 60; i < 63; ++i) r.v_true_m_s[i] = 140e-6;
  const VelocityMetrics m = velocity_metrics(r, 100e-6);
  EXPECT_TRUE(m.settled);
  EXPECT_NEAR(m.settling_time_s, r.t_s[14], 1e-12);  // the first 5-period mean inside +-5 %
  EXPECT_EQ(m.excursions, 7);                        // the windows that hold a burst period (3 + 5 - 1)
  EXPECT_NEAR(m.max_excursion_rel, 0.24, 1e-9);      // 3 x 40 % / 5
  // Never 20 periods inside: not settled.
  for (std::size_t i = 0; i < r.v_true_m_s.size(); ++i) r.v_true_m_s[i] = i % 15 == 0 ? 0.0 : 100e-6;
  EXPECT_FALSE(velocity_metrics(r, 100e-6).settled);
  EXPECT_THROW(velocity_metrics(r, 0.0), InvalidParams);  // no relative error against zero
}

TEST(VelocityControl, ThesisPidGetsThereSlowerAndOpenLoopCountingDoesNot) {
  for (double ref : {100e-6, -100e-6}) {
    std::vector<double> model_based, pid;
    for (int seed = 1; seed <= kSeeds; ++seed) {
      model_based.push_back(run_seed(VelocityMode::kModelBased, ref, 0.4, seed).metrics.settling_time_s);
      const auto p = run_seed(VelocityMode::kThesisPid, ref, 0.4, seed);
      EXPECT_LT(std::abs(p.metrics.steady_state_error_rel), 0.02) << seed;  // the integrator gets there ...
      pid.push_back(p.metrics.settling_time_s);
    }
    EXPECT_GT(median(pid), median(model_based)) << "ref " << ref;  // ... later
  }
  // A step assumed proportional to the amplitude misses the stick-slip threshold entirely or
  // lands far off: no feedback corrects it.
  const auto open = run_seed(VelocityMode::kOpenLoop, 100e-6, 0.4, 1);
  EXPECT_GT(std::abs(open.metrics.steady_state_error_rel), 0.2);
}

TEST(VelocityControl, VelocityEstimateUsesWholePeriods) {
  // With the estimate over N periods, the in-step oscillation does not enter: the estimate in
  // steady state stays within a few % of the true mean even with sensor noise.
  const auto run = run_velocity(test::model(), &test::step_map(), VelocityControlParams{},
                                VelocityMode::kModelBased, 100e-6, 0.2, kSensor);
  for (std::size_t i = run.t_s.size() / 2; i < run.t_s.size(); ++i) {
    EXPECT_NEAR(run.v_est_m_s[i], 100e-6, 10e-6) << "t " << run.t_s[i];
  }
}

TEST(VelocityControl, UpdateAndSawtoothDoNotAllocate) {
  VelocityController c(VelocityControlParams{}, VelocityMode::kModelBased, &test::step_map());
  c.set_reference(100e-6);
  double x = 0.0;
  mc::test::AllocationGuard guard;
  for (int k = 0; k < 2000; ++k) {
    c.update(x);
    for (int i = 0; i < 10; ++i) x += 1e-10 * c.next_drive(1e-5).end_V * 1e-3;
  }
  EXPECT_EQ(guard.allocations(), 0u);
}

TEST(VelocityControl, EndStopIsDetectedWithoutWindUpAndEmergencyStopZeroesTheDrive) {
  // Start 20 um before the forward stop: the slider reaches it and stalls.
  const double start = 0.5 * test::model().params().slider.stroke_m - 20e-6;
  const auto run = run_velocity(test::model(), &test::step_map(), VelocityControlParams{},
                                VelocityMode::kModelBased, 100e-6, 0.6, kSensor, start);
  EXPECT_EQ(run.amplitude_V.back(), 0.0);  // stopped driving once the end stop was detected
  // No wind-up: the amplitude never exceeded the output limit and was not held at it for long.
  int at_max = 0;
  for (double a : run.amplitude_V) {
    EXPECT_LE(a, 100.0);
    if (a >= 99.0) ++at_max;
  }
  // stall_periods consecutive stalled periods end it; a slider part that still creeps into the
  // stop (the modal parts are microns apart, docs/errata.md) restarts the count once or twice:
  // 26 periods at full amplitude in all with the default model (a part advanced 0.44 um after the
  // first stalled periods).
  EXPECT_LE(at_max, VelocityControlParams{}.stall_periods + 8);

  VelocityController c(VelocityControlParams{}, VelocityMode::kModelBased, &test::step_map());
  c.set_reference(100e-6);
  for (int k = 0; k < 500; ++k) {
    c.update(0.0);
    for (int i = 0; i < 10; ++i) c.next_drive(1e-5);
  }
  c.emergency_stop();
  EXPECT_EQ(c.next_drive(1e-5).end_V, 0.0);
}

TEST(VelocityControl, InvalidParamsAreRejected) {
  VelocityControlParams p;
  p.delay_periods = 0;
  EXPECT_THROW(VelocityController(p, VelocityMode::kThesisPid, nullptr), InvalidParams);
  EXPECT_THROW(VelocityController(VelocityControlParams{}, VelocityMode::kModelBased, nullptr),
               InvalidParams);
  EXPECT_THROW(parse_velocity_mode("fast"), UsageError);
}

}  // namespace
}  // namespace velocity_control_test
}  // namespace mc::motion
