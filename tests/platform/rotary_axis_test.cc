// The rotary axis under the gripper on the platform. The console turns it to a
// goal through the stick-slip model and the stage controller's fourth channel; nothing turns
// without the console's deadman; hold() and faults leave it holding at 0 V like the other axes.

#include <gtest/gtest.h>

#include <cmath>

#include "microcobot/platform/platform.h"

namespace mc::platform {
namespace {

struct RotaryRig {
  PlatformConfig config;
  std::unique_ptr<Platform> platform;
  teleop::ConsoleInput in;
  RotaryRig() {
    platform = std::make_unique<Platform>(config);
    in.active = in.fresh = in.deadman = true;
    in.has_theta_goal = true;
    in.theta_speed_rad_s = 0.16;
    platform->set_operator([this](const runtime::TickInfo&) { platform->set_console_input(in); });
    platform->set_console_input(in);
    platform->run(0.05);
  }
  double true_yaw() const { return platform->simulated_gripper()->yaw_rad(); }
  double channel(const char* name) const {
    const auto v = platform->recording().channel(name);
    return v.empty() ? std::nan("") : v.back();
  }
};

TEST(RotaryAxis, TheConsoleTurnsTheGripperToItsGoalAndItHoldsThere) {
  RotaryRig rig;
  ASSERT_TRUE(rig.platform->has_rotary());
  rig.in.theta_goal_rad = 0.5;  // 28.6 deg: 3.1 s at 0.16 rad/s
  rig.platform->run(1.0);
  const double mid = rig.true_yaw();
  EXPECT_NEAR(mid, 0.16, 0.02) << "turning at the asked speed";
  rig.platform->run(3.0);
  const double end = rig.true_yaw();
  std::printf("rotary: 1 s %.5f rad, 4 s %.7f rad (goal 0.5), measured %.7f\n", mid, end,
              rig.platform->yaw_rad());
  EXPECT_NEAR(end, 0.5, 2e-6) << "within 2 urad (10 nm of arc at 5 mm)";
  rig.platform->run(1.0);
  EXPECT_NEAR(rig.true_yaw(), end, 1e-6) << "holds";
  EXPECT_NEAR(rig.channel("target_theta_rad"), 0.5, 1e-12);
  // The last telemetry sample (a few ticks before the end): holding, within the noise.
  EXPECT_NEAR(rig.channel("slave_theta_rad"), rig.true_yaw(), 2e-6);
  EXPECT_NEAR(rig.channel("measured_theta_rad"), rig.platform->yaw_rad(), 2e-6);
  // Arrived, the axis is parked: its voltage held constant, friction holding the rotor.
  EXPECT_TRUE(rig.platform->parked(3));
  const auto u = rig.platform->recording().channel("u_theta_V");
  for (std::size_t i = u.size() - 100; i < u.size(); ++i) EXPECT_EQ(u[i], u.back());
  const double parked_at = rig.true_yaw();
  rig.platform->run(1.0);
  EXPECT_NEAR(rig.true_yaw(), parked_at, 1e-9) << "parked, it does not creep";
  // A new goal takes it out of the park without a jump.
  rig.in.theta_goal_rad = 0.4;
  rig.platform->run(0.01);
  EXPECT_FALSE(rig.platform->parked(3));
  EXPECT_LT(std::abs(rig.true_yaw() - parked_at), 0.16 * 0.01 + 1e-5);
  rig.platform->run(1.5);
  EXPECT_NEAR(rig.true_yaw(), 0.4, 2e-6);
}

TEST(RotaryAxis, NothingTurnsWithoutTheConsolesDeadman) {
  RotaryRig rig;
  rig.in.deadman = false;
  rig.in.theta_goal_rad = 0.5;
  const double start = rig.true_yaw();
  rig.platform->run(1.0);
  EXPECT_NEAR(rig.true_yaw(), start, 1e-6);
  // Let go in mid-turn: the target stops at once, the axis settles on it and stays.
  rig.in.deadman = true;
  rig.platform->run(1.0);
  rig.in.deadman = false;
  const double target = rig.platform->yaw_target_rad();
  rig.platform->run(0.5);
  const double settled = rig.true_yaw();
  EXPECT_NEAR(settled, target, 5e-4) << "the tracking lag, no more";
  rig.platform->run(1.0);
  EXPECT_NEAR(rig.true_yaw(), settled, 1e-6);
  EXPECT_EQ(rig.platform->yaw_target_rad(), target);
}

TEST(RotaryAxis, HoldAndFaultsLeaveItHoldingAtZeroVolts) {
  RotaryRig rig;
  rig.in.theta_goal_rad = -0.3;
  rig.platform->run(1.0);
  rig.platform->hold();
  EXPECT_NEAR(rig.platform->yaw_target_rad(), rig.platform->yaw_rad(), 1e-12);
  rig.in.deadman = false;
  rig.platform->run(0.5);
  const double held = rig.true_yaw();
  rig.platform->run(0.5);
  EXPECT_NEAR(rig.true_yaw(), held, 1e-6);
  rig.in.deadman = true;
  rig.platform->run(0.5);  // turning again
  rig.platform->fault_all();
  EXPECT_EQ(rig.platform->rotary_axis()->state(), devices::Lifecycle::kFault);
  const double at_fault = rig.true_yaw();
  rig.platform->run(0.5);
  EXPECT_EQ(rig.channel("u_theta_V"), 0.0);
  EXPECT_EQ(rig.platform->simulation().rotary->voltage_V(), 0.0);
  EXPECT_NEAR(rig.true_yaw(), at_fault, 2e-4) << "the rotor coasts to a stop on its friction";
}

TEST(RotaryAxis, ItCanBeLeftOutAndTheTelemetryThenReadsZero) {
  PlatformConfig c;
  c.stage.rotary.enabled = false;
  Platform p(c);
  EXPECT_FALSE(p.has_rotary());
  EXPECT_EQ(p.yaw_rad(), 0.0);
  p.run(0.01);
  EXPECT_EQ(p.simulated_gripper()->yaw_rad(), 0.0);
}

}  // namespace
}  // namespace mc::platform
