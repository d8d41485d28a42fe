// The rotary axis' command. The target moves only with the console's deadman
// held and fresh commands, at a bounded slew, within the axis' travel; hold_at() takes it where the
// axis is.

#include <gtest/gtest.h>

#include <cmath>

#include "microcobot/core/error.h"
#include "microcobot/teleop/rotary_target.h"

namespace mc::teleop {
namespace {

constexpr double kRotaryDt = 1e-4;

ConsoleInput turning(double goal_rad, double speed_rad_s) {
  ConsoleInput c;
  c.deadman = c.fresh = true;
  c.has_theta_goal = true;
  c.theta_goal_rad = goal_rad;
  c.theta_speed_rad_s = speed_rad_s;
  return c;
}

TEST(RotaryTarget, NothingTurnsWithoutTheDeadmanOrWithStaleCommands) {
  RotaryTarget t({}, kRotaryDt, 0.1, -1.0, 1.0);
  ConsoleInput c = turning(0.5, 0.1);
  c.deadman = false;
  for (int i = 0; i < 1000; ++i) t.tick(c);
  EXPECT_EQ(t.target_rad(), 0.1);
  c.deadman = true;
  c.fresh = false;
  c.theta_rate_rad_s = 0.1;
  c.has_theta_goal = false;
  for (int i = 0; i < 1000; ++i) t.tick(c);
  EXPECT_EQ(t.target_rad(), 0.1);
  EXPECT_EQ(t.velocity_rad_s(), 0.0);
}

TEST(RotaryTarget, TurnsToItsGoalAtTheAskedSpeedWithinTheSlewLimit) {
  motion::RotaryAxisParams p;
  p.max_speed_rad_s = 0.2;
  RotaryTarget t(p, kRotaryDt, 0.0, -1.0, 1.0);
  // 0.05 rad/s asked: 0.1 s gives 5 mrad.
  for (int i = 0; i < 1000; ++i) t.tick(turning(0.3, 0.05));
  EXPECT_NEAR(t.target_rad(), 0.005, 1e-9);
  EXPECT_NEAR(t.velocity_rad_s(), 0.05, 1e-9);
  // 10 rad/s asked: the slew limit, 0.2 rad/s.
  for (int i = 0; i < 1000; ++i) t.tick(turning(0.3, 10.0));
  EXPECT_NEAR(t.target_rad(), 0.025, 1e-9);
  // Reaches the goal and stops there, at rest.
  for (int i = 0; i < 20000; ++i) t.tick(turning(0.3, 10.0));
  EXPECT_DOUBLE_EQ(t.target_rad(), 0.3);
  EXPECT_EQ(t.velocity_rad_s(), 0.0);
}

TEST(RotaryTarget, StaysWithinTheTravelAndTakesTheAxisWhereItIs) {
  RotaryTarget t({}, kRotaryDt, 0.0, -0.5, 0.5);
  for (int i = 0; i < 100000; ++i) t.tick(turning(3.0, 0.16));
  EXPECT_DOUBLE_EQ(t.target_rad(), 0.5);
  ConsoleInput dial;
  dial.deadman = dial.fresh = true;
  dial.theta_rate_rad_s = -100.0;  // beyond the slew limit: clamped
  t.tick(dial);
  EXPECT_NEAR(t.target_rad(), 0.5 - 0.16 * kRotaryDt, 1e-12);
  t.hold_at(0.2);
  EXPECT_EQ(t.target_rad(), 0.2);
  EXPECT_EQ(t.velocity_rad_s(), 0.0);
  t.hold_at(9.0);
  EXPECT_EQ(t.target_rad(), 0.5);
}

// A yaw stop (shared control of a turn): the dial turning steadily through the stop's yaw; within its
// capture the target sits there, beyond twice it the dial has it back; it fades in without a jump.
TEST(RotaryTarget, AYawStopHoldsTheDialWithinItsCaptureAndFadesInWithoutAJump) {
  RotaryTarget t({}, kRotaryDt, 0.0, -1.0, 1.0);
  ConsoleInput dial;
  dial.deadman = dial.fresh = true;
  dial.theta_rate_rad_s = 0.05;
  for (int i = 0; i < 1000; ++i) t.tick(dial);  // 0.1 s: 5 mrad
  const double before = t.target_rad();
  t.set_stop(true, 0.1, 1.0, 0.02, 2.0);
  t.tick(dial);
  EXPECT_NEAR(t.target_rad(), before + 0.05 * kRotaryDt, 1e-9) << "installed: no jump";
  double largest_step = 0.0, last = t.target_rad(), at_stop_s = 0.0;
  for (int i = 0; i < 40000; ++i) {  // 4 s more: the dial to 205 mrad
    t.tick(dial);
    largest_step = std::max(largest_step, std::abs(t.target_rad() - last));
    last = t.target_rad();
    if (std::abs(t.target_rad() - 0.1) < 1e-6) at_stop_s += kRotaryDt;
  }
  // Held at the stop while the dial crossed its capture (0.08-0.12 rad at 50 mrad/s: 0.8 s, less
  // the fades), then the dial's again: 41001 ticks at 5 urad, 0.205005 rad.
  EXPECT_GT(at_stop_s, 0.5);
  EXPECT_NEAR(t.target_rad(), 0.205005, 1e-9);
  EXPECT_LE(largest_step, motion::RotaryAxisParams{}.max_speed_rad_s * kRotaryDt * (1 + 1e-9))
      << "within the slew limit";
  // Let go (the deadman released), the dial starts again from where the target is.
  dial.deadman = false;
  t.tick(dial);
  dial.deadman = true;
  t.set_stop(false, 0.0, 0.0, 0.02, 2.0);
  t.tick(dial);
  EXPECT_NEAR(t.target_rad(), 0.205005 + 0.05 * kRotaryDt, 1e-9);
}

TEST(RotaryAxisParams, BadValuesAreRefusedNamingTheField) {
  motion::RotaryAxisParams p;
  p.radius_m = 0.0;
  EXPECT_THROW(
      {
        try {
          p.validate();
        } catch (const InvalidParams& e) {
          EXPECT_NE(std::string(e.what()).find("radius_m"), std::string::npos);
          throw;
        }
      },
      InvalidParams);
  p = {};
  p.max_speed_rad_s = std::nan("");
  EXPECT_THROW(p.validate(), InvalidParams);
  EXPECT_THROW(RotaryTarget(motion::RotaryAxisParams{}, kRotaryDt, 2.0, -1.0, 1.0), InvalidParams);
}

TEST(RotaryAxisParams, TheAngleIsTheArcOverTheContactRadius) {
  motion::RotaryAxisParams p;
  p.radius_m = 5e-3;
  p.home_rad = 0.1;
  EXPECT_DOUBLE_EQ(p.angle_rad(5e-3), 1.1);
  EXPECT_DOUBLE_EQ(p.arc_m(p.angle_rad(1.234e-4)), 1.234e-4);
}

}  // namespace
}  // namespace mc::teleop
