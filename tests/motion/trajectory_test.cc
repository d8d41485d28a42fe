// Trajectory tracking with the hybrid controller under velocity and acceleration limits.
#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "control_fixture.h"
#include "microcobot/motion/closed_loop.h"

namespace mc::motion {
namespace {

TEST(Trajectory, TrapezoidIsTrackedWithinAStepAndEndsOnTarget) {
  const MotionLimits lim{200e-6, 2e-3};
  auto limiter = std::make_shared<ReferenceLimiter>(lim, 0.0);
  const double d = 50e-6;
  PositionControlParams p;
  p.scan_velocity_m_s = 1.5 * lim.max_velocity_m_s;
  p.scan_acceleration_m_s2 = 0.05;
  const auto run = run_tracking(
      test::model(), test::step_map(), p, PositionSensorParams{}, 0.0,
      [limiter, d](double, double dt) { return limiter->step(d, dt); }, trapezoid_duration_s(d, lim) + 0.05);
  EXPECT_LT(run.max_error_m, 3.5e-6);  // within about two PE strokes while moving
  EXPECT_LT(run.rms_error_m, 1.5e-6);
  EXPECT_NEAR(run.x_m.back(), d, 5e-9);  // and on target at the end
}

TEST(Trajectory, SineIsTracked) {
  const MotionLimits lim{200e-6, 2e-3};
  const SineReference sine(0.0, 20e-6, 1.0, lim);
  PositionControlParams p;
  p.scan_velocity_m_s = 300e-6;
  p.scan_acceleration_m_s2 = 0.05;
  const auto run = run_tracking(
      test::model(), test::step_map(), p, PositionSensorParams{}, 0.0,
      [&sine](double t, double) { return sine.at(t); }, 1.0);
  EXPECT_LT(run.rms_error_m, 0.1 * 20e-6);
  EXPECT_LT(run.max_error_m, 0.3 * 20e-6);
}

}  // namespace
}  // namespace mc::motion
