#include "microcobot/teleop/teleoperation.h"

#include <gtest/gtest.h>

#include <array>
#include <random>

#include "microcobot/core/error.h"

namespace mc::teleop {
// The file's own namespace: its helpers keep their names beside the other test files of the
// module in a unity build (MC_UNITY_TESTS).
namespace teleoperation_test {
namespace {

constexpr double kDt = 1e-4;

TeleoperationInput engaged_at(double x, double y) {
  TeleoperationInput in;
  in.handle_m = {x, y};
  in.deadman = true;
  in.tweezers_opening_m = 10e-3;
  return in;
}

TEST(Teleoperation, EngagingNeverMovesTheSlaveThenMotionIsScaled) {
  Teleoperation t(TeleoperationParams{}, kDt, {1e-3, -2e-3, 0.5e-3}, 600e-6);
  auto out = t.tick(engaged_at(0.02, 0.01));  // the hand is anywhere when the deadman is pressed
  EXPECT_TRUE(out.engaged);
  EXPECT_DOUBLE_EQ(out.slave_target_m.x(), 1e-3);
  EXPECT_DOUBLE_EQ(out.slave_target_m.y(), -2e-3);
  out = t.tick(engaged_at(0.021, 0.008));  // +1 mm, -2 mm of hand
  EXPECT_NEAR(out.slave_target_m.x(), 1e-3 + 10e-6, 1e-15);
  EXPECT_NEAR(out.slave_target_m.y(), -2e-3 - 20e-6, 1e-15);
  // Feedforward of the moving target, low-passed (velocity_filter_s): one tick's step counts by
  // 1 - exp(-dt / tau) of its speed.
  const double alpha = 1.0 - std::exp(-kDt / TeleoperationParams{}.velocity_filter_s);
  EXPECT_NEAR(out.slave_velocity_m_s.x(), alpha * 10e-6 / kDt, 1e-9);
  EXPECT_DOUBLE_EQ(out.slave_target_m.z(), 0.5e-3);
}

TEST(Teleoperation, ClutchingIndexesTheHandWhileTheSlaveHolds) {
  Teleoperation t(TeleoperationParams{}, kDt, {0, 0, 0}, 600e-6);
  t.tick(engaged_at(0.0, 0.0));
  t.tick(engaged_at(0.03, 0.0));  // slave at 300 um
  auto in = engaged_at(0.03, 0.0);
  in.clutch = true;
  for (double x = 0.03; x > -0.03; x -= 0.001) {
    in.handle_m.x() = x;
    const auto& out = t.tick(in);
    EXPECT_FALSE(out.engaged);
    EXPECT_NEAR(out.slave_target_m.x(), 300e-6, 1e-15);
  }
  auto out = t.tick(engaged_at(-0.03, 0.0));  // released: re-indexed, no jump
  EXPECT_NEAR(out.slave_target_m.x(), 300e-6, 1e-15);
  out = t.tick(engaged_at(0.0, 0.0));  // another 30 mm stroke reaches 600 um
  EXPECT_NEAR(out.slave_target_m.x(), 600e-6, 1e-12);
}

TEST(Teleoperation, ForcesAreScaledFilteredAndCapped) {
  TeleoperationParams p;
  Teleoperation t(p, kDt, {0, 0, 0}, 600e-6);
  auto in = engaged_at(0, 0);
  in.contact_force_N = {36e-6, 0, 0};
  // First-order filter: 63 % after one time constant 1 / (2 pi 30 Hz).
  const int tau_ticks = static_cast<int>(std::round(1.0 / (2 * M_PI * p.force_filter_Hz) / kDt));
  for (int i = 0; i < tau_ticks; ++i) t.tick(in);
  EXPECT_NEAR(t.output().haptic_force_N.x(), 0.36 * (1 - std::exp(-1.0)), 0.01);
  for (int i = 0; i < 20 * tau_ticks; ++i) t.tick(in);
  EXPECT_NEAR(t.output().haptic_force_N.x(), 0.36, 1e-6);  // 36 uN x 1e4
  in.contact_force_N = {0, -1e-3, 0};                      // 10 N scaled: capped at max_force_N
  for (int i = 0; i < 20 * tau_ticks; ++i) t.tick(in);
  EXPECT_NEAR(t.output().haptic_force_N.norm(), p.max_force_N, 1e-9);
  in.grip_force_N = 1e-3;
  EXPECT_NEAR(t.tick(in).finger_force_N, 0.1, 1e-12);  // x 100
  in.grip_force_N = 1.0;
  EXPECT_DOUBLE_EQ(t.tick(in).finger_force_N, p.max_grip_force_N);
}

TEST(Teleoperation, DeadmanReleasedOrStaleMasterHoldsTheSlaveWithZeroForce) {
  Teleoperation t(TeleoperationParams{}, kDt, {0, 0, 0}, 600e-6);
  auto in = engaged_at(0, 0);
  in.contact_force_N = {36e-6, 0, 0};
  for (int i = 0; i < 1000; ++i) t.tick(in);
  in.handle_m.x() = 0.01;
  const double held = t.tick(in).slave_target_m.x();
  EXPECT_GT(t.output().haptic_force_N.x(), 0.0);
  in.deadman = false;
  in.handle_m.x() = 0.02;
  auto out = t.tick(in);
  EXPECT_FALSE(out.engaged);
  EXPECT_DOUBLE_EQ(out.slave_target_m.x(), held);
  EXPECT_DOUBLE_EQ(out.haptic_force_N.norm(), 0.0);
  in.deadman = true;
  in.haptic_fresh = false;
  out = t.tick(in);
  EXPECT_TRUE(out.stale);
  EXPECT_FALSE(out.engaged);
  EXPECT_DOUBLE_EQ(out.slave_target_m.x(), held);
  EXPECT_DOUBLE_EQ(out.haptic_force_N.norm(), 0.0);
}

TEST(Teleoperation, ASilentSlaveReleasesBothMastersAndReEngagesWhereItNowIs) {
  Teleoperation t(TeleoperationParams{}, kDt, {0, 0, 0}, 600e-6);
  auto in = engaged_at(0.0, 0.0);
  in.contact_force_N = {50e-6, 0, 0};  // 0.5 N on the hand
  in.grip_force_N = 5e-3;              // 0.5 N on the fingers
  for (int i = 0; i < 1000; ++i) t.tick(in);
  ASSERT_GT(t.output().haptic_force_N.x(), 0.4);
  ASSERT_GT(t.output().finger_force_N, 0.4);
  // The slave falls silent (a remote slave's link): no force on either master at once.
  in.slave_fresh = false;
  in.handle_m.x() = 0.02;  // the hand moves on meanwhile
  auto out = t.tick(in);
  EXPECT_FALSE(out.engaged);
  EXPECT_TRUE(out.stale);
  EXPECT_EQ(out.haptic_force_N.norm(), 0.0);
  EXPECT_EQ(out.finger_force_N, 0.0);
  EXPECT_EQ(out.slave_target_m.x(), 0.0) << "the target holds";
  // It returns elsewhere (a restarted slave at its home): the target is re-taken from where it
  // is, and the hand's new position does not move it (re-indexed like a clutch).
  in.slave_fresh = true;
  in.slave_position_m = {-150e-6, 20e-6, 5e-6};
  out = t.tick(in);
  EXPECT_TRUE(out.engaged);
  EXPECT_NEAR((out.slave_target_m - in.slave_position_m).norm(), 0.0, 1e-15);
  in.handle_m.x() = 0.021;  // +1 mm of hand: +10 um from there
  out = t.tick(in);
  EXPECT_NEAR(out.slave_target_m.x(), -150e-6 + 10e-6, 1e-15);
}

TEST(Teleoperation, TweezersDriveTheGripperAndStaleTweezersHoldIt) {
  Teleoperation t(TeleoperationParams{}, kDt, {0, 0, 0}, 600e-6);
  auto in = engaged_at(0, 0);
  in.tweezers_opening_m = 5e-3;
  EXPECT_NEAR(t.tick(in).gripper_opening_m, 300e-6, 1e-15);  // x 0.06
  in.tweezers_opening_m = 2e-3;
  in.tweezers_fresh = false;
  in.grip_force_N = 1e-3;
  const auto& out = t.tick(in);
  EXPECT_NEAR(out.gripper_opening_m, 300e-6, 1e-15);
  EXPECT_DOUBLE_EQ(out.finger_force_N, 0.0);
}

TEST(Teleoperation, JogIntegratesZAndTargetsStayInTheWorkspace) {
  TeleoperationParams p;
  Teleoperation t(p, kDt, {0, 0, 0}, 600e-6);
  auto in = engaged_at(0, 0);
  in.z_jog_m_s = 1.0;  // far above the limit
  for (int i = 0; i < 10000; ++i) t.tick(in);
  EXPECT_NEAR(t.output().slave_target_m.z(), p.max_jog_m_s * 1.0, 1e-9);
  in.handle_m.x() = 10.0;  // 100 mm of slave: clamped to the stroke
  EXPECT_DOUBLE_EQ(t.tick(in).slave_target_m.x(), p.workspace_max_m);
}

TEST(Teleoperation, RejectsBadParameters) {
  TeleoperationParams p;
  p.motion_scale = 0;
  EXPECT_THROW(Teleoperation(p, kDt, {0, 0, 0}, 0), InvalidParams);
  p = {};
  p.workspace_min_m = 1e-3;
  p.workspace_max_m = -1e-3;
  EXPECT_THROW(p.validate(), InvalidParams);
  EXPECT_THROW(Teleoperation(TeleoperationParams{}, 0.0, {0, 0, 0}, 0), InvalidParams);
}

TeleoperationInput console_at(double vx, bool deadman = true) {
  TeleoperationInput in;
  in.console.active = true;
  in.console.fresh = true;
  in.console.deadman = deadman;
  in.console.velocity_m_s = {vx, 0, 0};
  in.handle_m = {0.04, 0.04};  // the haptic handle is ignored while the console holds control
  return in;
}

TEST(Teleoperation, TheConsoleJogsTheStageAtItsVelocityCappedAndOnlyWithTheDeadman) {
  TeleoperationParams p;
  Teleoperation t(p, kDt, {0, 0, 0}, 600e-6);
  for (int i = 0; i < 1000; ++i) t.tick(console_at(200e-6));  // 0.1 s at 200 um/s
  EXPECT_NEAR(t.output().slave_target_m.x(), 20e-6, 1e-12);
  EXPECT_NEAR(t.output().slave_velocity_m_s.x(), 200e-6, 1e-12);
  EXPECT_DOUBLE_EQ(t.output().haptic_force_N.norm(), 0.0);
  for (int i = 0; i < 1000; ++i) t.tick(console_at(1.0));  // 1 m/s asked: the cap holds
  EXPECT_NEAR(t.output().slave_target_m.x(), 20e-6 + p.console_max_speed_m_s * 0.1, 1e-12);
  const double held = t.output().slave_target_m.x();
  for (int i = 0; i < 100; ++i) t.tick(console_at(200e-6, /*deadman=*/false));
  EXPECT_FALSE(t.output().engaged);
  EXPECT_DOUBLE_EQ(t.output().slave_target_m.x(), held);
  auto stale = console_at(200e-6);
  stale.console.fresh = false;  // the watchdog: stale commands hold the stage
  for (int i = 0; i < 100; ++i) t.tick(stale);
  EXPECT_TRUE(t.output().stale);
  EXPECT_DOUBLE_EQ(t.output().slave_target_m.x(), held);
}

TEST(Teleoperation, TheGrippersReleaseBurstPassesOnlyFromAnEngagedConsoleThatHasTheGripper) {
  Teleoperation t(TeleoperationParams{}, kDt, {0, 0, 0}, 600e-6);
  auto in = console_at(0.0);
  in.console.has_gripper = true;
  in.console.gripper_opening_m = 600e-6;
  in.console.gripper_shake = true;
  EXPECT_TRUE(t.tick(in).gripper_shake);
  in.console.deadman = false;  // nothing of the slave moves without the deadman, the fingers neither
  EXPECT_FALSE(t.tick(in).gripper_shake);
  in.console.deadman = true;
  in.console.fresh = false;  // stale commands
  EXPECT_FALSE(t.tick(in).gripper_shake);
  in.console.fresh = true;
  in.console.has_gripper = false;  // the TéléTweez has the gripper
  EXPECT_FALSE(t.tick(in).gripper_shake);
  in.console.has_gripper = true;
  in.console.active = false;  // the haptic master holds control
  in.deadman = true;
  EXPECT_FALSE(t.tick(in).gripper_shake);
}

// A neighbouring part's keep-out region (virtual_fixtures.h): a hand that sweeps the slave across
// it low, trembling (8-12 Hz, 100 um RMS at the hand) and rolling the wheel down, never
// puts the target inside; above the part's top it passes over; nothing jumps on leaving.
TEST(Teleoperation, UnderTremorTheTargetNeverEntersANeighboursKeepOutAndNeverJumps) {
  TeleoperationParams p;
  Teleoperation t(p, kDt, {-400e-6, 0, 200e-6}, 600e-6);
  FixtureSet f;
  f.keep_out_count = 2;
  f.keep_outs[0] = {{0.0, 0.0}, 250e-6, 650e-6};
  f.keep_outs[1] = {{600e-6, 100e-6}, 250e-6, 400e-6};
  t.set_fixtures(f);
  std::mt19937_64 rng(20261128);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  // Tremor: three sines in 8-12 Hz of random phases, 100 um RMS per axis at the hand.
  std::array<double, 6> hz{}, phase{};
  for (std::size_t i = 0; i < 6; ++i) {
    hz[i] = 8.0 + 4.0 * u(rng);
    phase[i] = 2 * M_PI * u(rng);
  }
  const double a = 100e-6 * std::sqrt(2.0 / 3.0);
  auto in = engaged_at(0.0, 0.0);
  int held = 0;
  double largest_step = 0.0;
  Eigen::Vector3d last = t.tick(in).slave_target_m;
  for (int k = 1; k < 200000; ++k) {  // 20 s
    const double s = k * kDt;
    // The hand sweeps +-60 mm (+-600 um of slave) at 0.05 Hz, its y wandering; the wheel goes
    // down for 15 s (towards 0), then up.
    double x = 0.06 * std::sin(2 * M_PI * 0.05 * s), y = 0.02 * std::sin(2 * M_PI * 0.13 * s);
    for (std::size_t i = 0; i < 3; ++i) x += a * std::sin(2 * M_PI * hz[i] * s + phase[i]);
    for (std::size_t i = 3; i < 6; ++i) y += a * std::sin(2 * M_PI * hz[i] * s + phase[i]);
    in.handle_m = {x, y};
    in.z_jog_m_s = s < 15.0 ? -40e-6 : 100e-6;
    const Eigen::Vector3d now = t.tick(in).slave_target_m;
    for (int i = 0; i < f.keep_out_count; ++i) {
      const auto& ko = f.keep_outs[static_cast<std::size_t>(i)];
      ASSERT_FALSE(now.z() < ko.top_z_m && (now.head<2>() - ko.xy_m).norm() < ko.radius_m * (1 - 1e-12))
          << "inside region " << i << " at " << s << " s";
    }
    for (int i = 0; i < f.keep_out_count; ++i) {
      const auto& ko = f.keep_outs[static_cast<std::size_t>(i)];
      if (now.z() < ko.top_z_m && std::abs((now.head<2>() - ko.xy_m).norm() - ko.radius_m) < 1e-9) ++held;
    }
    if (k > 1) largest_step = std::max(largest_step, (now - last).norm());  // the first: the tremor's start
    last = now;
  }
  // The hand's fastest motion is 2 pi 0.05 x 60 mm x 0.01 = 190 um/s of slave plus the tremor's
  // ~60 um/s: a tick moves at most ~30 nm; a jump out of a region would be hundreds of um.
  EXPECT_LT(largest_step, 0.1e-6);
  EXPECT_GT(held, 1000) << "ticks held on a region's edge: the sweep must reach the regions";
}

TEST(Teleoperation, ClickToGoMovesStraightToTheGoalAndLandsOnIt) {
  Teleoperation t(TeleoperationParams{}, kDt, {0, 0, 0}, 600e-6);
  auto in = console_at(0.0);
  in.console.has_goal = true;
  in.console.goal_m = {30e-6, 40e-6, 0};  // 50 um away
  in.console.goal_speed_m_s = 100e-6;
  for (int i = 0; i < 2500; ++i) {  // half way after 0.25 s
    t.tick(in);
  }
  EXPECT_NEAR(t.output().slave_target_m.x(), 15e-6, 1e-10);
  EXPECT_NEAR(t.output().slave_target_m.y(), 20e-6, 1e-10);
  for (int i = 0; i < 3000; ++i) t.tick(in);
  EXPECT_DOUBLE_EQ(t.output().slave_target_m.x(), 30e-6);
  EXPECT_DOUBLE_EQ(t.output().slave_target_m.y(), 40e-6);
  EXPECT_DOUBLE_EQ(t.output().slave_velocity_m_s.norm(), 0.0);
}

TEST(Teleoperation, HandingControlBackToTheHapticMasterNeverMovesTheSlave) {
  Teleoperation t(TeleoperationParams{}, kDt, {0, 0, 0}, 600e-6);
  for (int i = 0; i < 1000; ++i) t.tick(console_at(100e-6));
  const Eigen::Vector3d at = t.output().slave_target_m;
  auto out = t.tick(engaged_at(0.03, -0.02));  // the hand is elsewhere: re-indexed
  EXPECT_NEAR((out.slave_target_m - at).norm(), 0.0, 1e-15);
  out = t.tick(engaged_at(0.031, -0.02));
  EXPECT_NEAR(out.slave_target_m.x(), at.x() + 10e-6, 1e-12);
}

}  // namespace
}  // namespace teleoperation_test
}  // namespace mc::teleop
