// Sawtooth synthesis, PID anti-windup, position sensor, reference limiter, step map.
#include <cmath>

#include <gtest/gtest.h>

#include "control_fixture.h"
#include "microcobot/core/error.h"
#include "microcobot/motion/pid.h"
#include "microcobot/motion/position_sensor.h"
#include "microcobot/motion/reference.h"
#include "microcobot/motion/sawtooth_generator.h"
#include "support/counting_allocator.h"

namespace mc::motion {
namespace {

TEST(SawtoothGenerator, ForwardPeriodRisesSlowlyAndDropsAtTheSlewRate) {
  SawtoothGenerator g(1.0e6);
  g.command(50.0, 1000.0, Direction::kForward);
  g.start(0.0);
  const double dt = 1e-6;
  double peak = 0.0, max_rise = 0.0, max_drop = 0.0, u_prev = 0.0;
  for (int i = 0; i < 1000; ++i) {
    const double u = g.next(dt).end_V;
    peak = std::max(peak, u);
    max_rise = std::max(max_rise, u - u_prev);
    max_drop = std::max(max_drop, u_prev - u);
    u_prev = u;
  }
  EXPECT_NEAR(peak, 50.0, 1e-9);
  EXPECT_NEAR(max_drop, 1.0, 1e-9);                         // slew 1 V/us
  EXPECT_NEAR(max_rise, 50.0 / (1e-3 - 50e-6) * dt, 1e-9);  // slow ramp over T - edge
  EXPECT_EQ(g.periods(), 1);
  EXPECT_NEAR(g.output_V(), 0.0, 1e-9);
}

TEST(SawtoothGenerator, BackwardIsTheMirrorAndCommandsLatchAtPeriodBoundaries) {
  SawtoothGenerator g(1.0e6);
  g.command(40.0, 1000.0, Direction::kBackward);
  g.start(0.0);
  const double dt = 1e-6;
  double u_prev = 0.0, max_jump = 0.0;
  for (int i = 0; i < 500; ++i) u_prev = g.next(dt).end_V;
  g.command(80.0, 2000.0, Direction::kForward);  // mid-period: must not change this period
  EXPECT_DOUBLE_EQ(g.amplitude_V(), 40.0);
  for (int i = 0; i < 3000; ++i) {
    const double u = g.next(dt).end_V;
    if (g.direction() == Direction::kForward) max_jump = std::max(max_jump, u - u_prev);
    u_prev = u;
  }
  EXPECT_DOUBLE_EQ(g.amplitude_V(), 80.0);
  EXPECT_LT(max_jump,
            80.0 / (0.5e-3 - 80e-6) * dt * 1.01);  // forward: the rise is slow (T - edge), never a jump
}

TEST(SawtoothGenerator, StartsBumplessFromAScanVoltageAndCountsZeroAmplitudePeriods) {
  SawtoothGenerator g(1.0e6);
  g.command(60.0, 1000.0, Direction::kForward);
  g.start(30.0);
  EXPECT_NEAR(g.next(1e-6).end_V, 30.0, 0.1);
  SawtoothGenerator z(1.0e6);
  z.command(0.0, 1000.0, Direction::kForward);
  z.start(0.0);
  for (int i = 0; i < 5000; ++i) EXPECT_EQ(z.next(1e-6).end_V, 0.0);
  EXPECT_EQ(z.periods(), 5);
}

TEST(Pid, ConditionalIntegrationStopsWindUpAtTheLimit) {
  Pid pid(PidParams{1.0, 100.0, 0.0, 0.0, 0.0, 10.0});
  for (int i = 0; i < 1000; ++i) EXPECT_LE(pid.update(50.0, 1e-3), 10.0);
  EXPECT_LE(pid.integral(), 10.0 + 1e-9);
  // Once the error reverses, the output leaves the limit at once (no stored wind-up).
  EXPECT_LT(pid.update(-5.0, 1e-3), 10.0);
  EXPECT_THROW(Pid(PidParams{-1.0, 0.0, 0.0, 0.0, 0.0, 1.0}), InvalidParams);
}

TEST(PositionSensor, QuantisesToTheResolutionWithTheConfiguredNoise) {
  PositionSensor exact(PositionSensorParams{0.1e-9, 0.0, 1});
  EXPECT_NEAR(exact.measure(1.234567e-6), 1.2346e-6, 1e-15);
  PositionSensor noisy(PositionSensorParams{0.1e-9, 1e-9, 3});
  double s = 0.0, s2 = 0.0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const double e = noisy.measure(5e-6) - 5e-6;
    s += e;
    s2 += e * e;
  }
  EXPECT_NEAR(s / n, 0.0, 5e-11);
  EXPECT_NEAR(std::sqrt(s2 / n), 1e-9, 0.03e-9);
  EXPECT_THROW(PositionSensor(PositionSensorParams{0.0, 1e-9, 1}), InvalidParams);
}

TEST(ReferenceLimiter, TrapezoidRespectsTheLimitsAndStopsOnTheSetpoint) {
  const MotionLimits lim{200e-6, 2e-3};
  ReferenceLimiter r(lim, 0.0);
  const double dt = 1e-4, d = 100e-6;
  double t = 0.0, vmax = 0.0, amax = 0.0, xmax = 0.0, v_prev = 0.0;
  while (t < 1.0) {
    const auto s = r.step(d, dt);
    vmax = std::max(vmax, std::abs(s.v_m_s));
    amax = std::max(amax, std::abs(s.v_m_s - v_prev) / dt);
    xmax = std::max(xmax, s.x_m);
    v_prev = s.v_m_s;
    t += dt;
    if (s.x_m == d && s.v_m_s == 0.0) break;
  }
  EXPECT_LE(vmax, lim.max_velocity_m_s * (1 + 1e-12));
  EXPECT_LE(amax, lim.max_acceleration_m_s2 * (1 + 1e-9));
  EXPECT_LE(xmax, d + 1e-15);  // no overshoot
  EXPECT_NEAR(t, trapezoid_duration_s(d, lim), 0.01 * trapezoid_duration_s(d, lim));
  EXPECT_THROW(SineReference(0.0, 1e-3, 1.0, lim), InvalidParams);  // 6.3 mm/s > 200 um/s
  mc::test::AllocationGuard guard;
  for (int i = 0; i < 100; ++i) r.step(-d, dt);
  EXPECT_EQ(guard.allocations(), 0u);
}

TEST(StepMap, ForwardAndBackwardStepsGrowWithTheAmplitudeAboveAThreshold) {
  const auto& map = test::step_map();
  for (auto dir : {Direction::kForward, Direction::kBackward}) {
    const double a_min = map.min_stepping_amplitude_V(1000.0, dir);
    EXPECT_GT(a_min, 30.0);  // below it the slider only follows the PE (scanning)
    EXPECT_LT(a_min, 80.0);
    EXPECT_GT(map.step_m(100.0, 1000.0, dir), 100e-9);
    EXPECT_GE(map.step_m(90.0, 1000.0, dir), map.step_m(70.0, 1000.0, dir));
    // The inverse lands on the step it was asked for.
    const double want = 0.5 * map.max_step_m(1000.0, dir);
    EXPECT_NEAR(map.step_m(map.amplitude_for_step(want, 1000.0, dir), 1000.0, dir), want, 1e-3 * want);
  }
  // Raw steps carry the drive's sign.
  const auto& fwd = map.signed_steps(Direction::kForward);
  EXPECT_GT(fwd.back()[1], 0.0);
}

}  // namespace
}  // namespace mc::motion
