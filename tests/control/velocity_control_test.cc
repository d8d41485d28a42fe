// Velocity control of thesis §2.7 (Fig. 2.18-2.19): 100 um/s forward and backward.
#include <cmath>

#include <gtest/gtest.h>

#include "control_fixture.h"
#include "microcobot/control/closed_loop.h"
#include "microcobot/core/error.h"
#include "support/counting_allocator.h"

namespace mc::control {
namespace {

const PositionSensorParams kSensor{};  // 0.1 nm resolution, 1 nm RMS noise

TEST(VelocityControl, ModelBasedPidReaches100umPerSecondBothWaysWithin2Percent) {
  for (double ref : {100e-6, -100e-6}) {
    const auto run = run_velocity(test::model(), &test::step_map(), VelocityControlParams{},
                                  VelocityMode::kModelBased, ref, 0.3, kSensor);
    const auto& m = run.metrics;
    EXPECT_LT(std::abs(m.steady_state_error_rel), 0.02) << "ref " << ref;  // issue goal
    EXPECT_TRUE(m.settled);
    EXPECT_LT(m.settling_time_s, 0.1);
    EXPECT_LT(m.ripple_m_s, 0.1 * std::abs(ref));
    EXPECT_GT(m.mean_velocity_m_s * ref, 0.0);  // the right direction
  }
}

TEST(VelocityControl, ThesisPidGetsThereSlowerAndOpenLoopCountingDoesNot) {
  const VelocityControlParams p;
  const auto model_based =
      run_velocity(test::model(), &test::step_map(), p, VelocityMode::kModelBased, 100e-6, 0.4, kSensor);
  const auto pid = run_velocity(test::model(), nullptr, p, VelocityMode::kThesisPid, 100e-6, 0.4, kSensor);
  const auto open = run_velocity(test::model(), nullptr, p, VelocityMode::kOpenLoop, 100e-6, 0.4, kSensor);
  EXPECT_LT(std::abs(pid.metrics.steady_state_error_rel), 0.02);  // the integrator gets there ...
  EXPECT_GT(pid.metrics.settling_time_s, model_based.metrics.settling_time_s);  // ... later
  // A step assumed proportional to the amplitude misses the stick-slip threshold entirely or
  // lands far off: no feedback corrects it.
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
    for (int i = 0; i < 10; ++i) x += 1e-10 * c.next_voltage(1e-5) * 1e-3;
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
  EXPECT_LE(at_max, VelocityControlParams{}.stall_periods + 2);

  VelocityController c(VelocityControlParams{}, VelocityMode::kModelBased, &test::step_map());
  c.set_reference(100e-6);
  for (int k = 0; k < 500; ++k) {
    c.update(0.0);
    for (int i = 0; i < 10; ++i) c.next_voltage(1e-5);
  }
  c.emergency_stop();
  EXPECT_EQ(c.next_voltage(1e-5), 0.0);
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
}  // namespace mc::control
