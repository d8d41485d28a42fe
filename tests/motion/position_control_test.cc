// Hybrid position control: stepping -> scanning (PI inverse) -> hold, 10 nm to 10 mm, both ways.
#include <cmath>

#include <gtest/gtest.h>

#include "control_fixture.h"
#include "microcobot/core/error.h"
#include "microcobot/motion/closed_loop.h"
#include "support/counting_allocator.h"

namespace mc::motion {
namespace {

const PositionSensorParams kSensor{};  // 0.1 nm resolution, 1 nm RMS noise

void expect_goals(double start, double target) {
  const auto run =
      run_position(test::model(), test::step_map(), PositionControlParams{}, kSensor, start, target);
  const auto& m = run.metrics;
  SCOPED_TRACE(::testing::Message() << "move " << start << " -> " << target);
  EXPECT_TRUE(m.in_position);
  EXPECT_FALSE(m.end_stop);
  EXPECT_LE(m.final_error_m, 5e-9);  // goal
  EXPECT_LE(m.overshoot_m, 20e-9);   // goal
  // Hold: no stepping and no oscillation beyond the noise-driven jitter (no limit cycle).
  EXPECT_FALSE(m.stepped_in_hold);
  EXPECT_LT(m.hold_pp_m, 5e-9);
  EXPECT_LT(m.hold_voltage_pp_V, 0.5);
}

TEST(PositionControl, MeetsTheGoalsFrom10nmTo1mmForwardAndBackward) {
  for (double d : {10e-9, 100e-9, 1e-6, 10e-6, 100e-6, 1e-3}) {
    expect_goals(-1e-3, -1e-3 + d);
    expect_goals(1e-3, 1e-3 - d);
  }
}

TEST(PositionControl, LongMovesStepThenSwitchToScanning) {
  const auto run =
      run_position(test::model(), test::step_map(), PositionControlParams{}, kSensor, -2.5e-3, 2.5e-3);
  EXPECT_LE(run.metrics.final_error_m, 5e-9);
  EXPECT_LE(run.metrics.overshoot_m, 20e-9);
  EXPECT_GE(run.metrics.switches, 1);
  // Both modes appear in order: stepping first, hold last.
  bool stepped = false, scanned_after = false;
  for (double mode : run.mode) {
    if (mode == static_cast<double>(AxisMode::kStepping)) stepped = true;
    if (stepped && mode == static_cast<double>(AxisMode::kScanning)) scanned_after = true;
  }
  EXPECT_TRUE(stepped);
  EXPECT_TRUE(scanned_after);
  EXPECT_EQ(run.mode.back(), static_cast<double>(AxisMode::kHold));
  // Far from the target the axis moves at ~mm/s (2 kHz steps), not at the 1 kHz approach rate.
  EXPECT_LT(run.metrics.move_time_s, 5e-3 / 0.5e-3);
}

TEST(PositionControl, BaselinesMissWhatTheHybridControllerHits) {
  const double start = 0.0, target = 20e-6;
  const auto hybrid =
      run_position(test::model(), test::step_map(), PositionControlParams{}, kSensor, start, target);
  const double t = hybrid.t_s.back();
  const auto open = run_baseline_position(test::model(), BaselinePositionParams{},
                                          BaselineKind::kOpenLoopCounting, kSensor, start, target, t);
  const auto pid = run_baseline_position(test::model(), BaselinePositionParams{}, BaselineKind::kThesisPid,
                                         kSensor, start, target, t);
  EXPECT_GT(open.metrics.final_error_m, 100.0 * hybrid.metrics.final_error_m);
  EXPECT_GT(open.metrics.final_error_m, 50e-9);
  // Stepping alone cannot resolve less than a step: the PID dithers or stops off target.
  EXPECT_GT(pid.metrics.final_error_m + pid.metrics.overshoot_m, 20e-9);
}

TEST(PositionControl, UpdateAndVoltageDoNotAllocate) {
  PositionController c(PositionControlParams{}, test::model().params(), test::step_map());
  auto s = test::model().initial_state();
  PositionSensor sensor;
  c.set_target(30e-6);
  mc::test::AllocationGuard guard;
  for (int k = 0; k < 3000; ++k) {
    c.update(sensor.measure(test::model().slider_position(s)));
    for (int i = 0; i < 10; ++i) test::model().step(s, c.next_drive(1e-5));
  }
  EXPECT_EQ(guard.allocations(), 0u);
  EXPECT_NE(c.mode(), AxisMode::kIdle);
}

TEST(PositionControl, PiInverseFeedforwardIsExact) {
  PositionController c(PositionControlParams{}, test::model().params(), test::step_map());
  for (double y : {0.1e-6, 0.5e-6, 1.2e-6}) EXPECT_NEAR(c.pe_displacement_m(c.inverse_V(y)), y, 1e-14);
  EXPECT_EQ(c.inverse_V(-1.0), 0.0);
  EXPECT_EQ(c.inverse_V(1.0), 100.0);
}

TEST(PositionControl, EndStopIsReportedAndTheDriveGoesTo0V) {
  const double half = 0.5 * test::model().params().slider.stroke_m;
  const auto run = run_position(test::model(), test::step_map(), PositionControlParams{}, kSensor,
                                half - 30e-6, half + 0.5e-3, 0.03, 0.5);
  EXPECT_TRUE(run.metrics.end_stop);
  EXPECT_FALSE(run.metrics.in_position);
  EXPECT_EQ(run.u_V.back(), 0.0);
  EXPECT_EQ(run.mode.back(), static_cast<double>(AxisMode::kEndStop));
}

TEST(PositionControl, InvalidParamsAreRejected) {
  PositionControlParams p;
  p.reach_margin = 1.5;
  EXPECT_THROW(PositionController(p, test::model().params(), test::step_map()), InvalidParams);
  EXPECT_THROW(run_position(test::model(), test::step_map(), PositionControlParams{}, kSensor, 0.0, 1.0),
               InvalidParams);
}

}  // namespace
}  // namespace mc::motion
