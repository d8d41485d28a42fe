#include "microcobot/teleop/safety_limits.h"

#include <gtest/gtest.h>

#include <limits>

#include "microcobot/core/error.h"
#include "microcobot/microworld/piezo_gripper.h"
#include "microcobot/teleop/teleoperation.h"

namespace mc::teleop {
namespace {

constexpr double kDt = 1e-4;

// The force-controlled close on the gripper's own model: fingers commanded shut on a 300 um
// part stop where the grip reaches its limit, whatever the command's speed.
TEST(SafetyLimits, AGripperSlammedShutOnAPartStopsAtTheForceLimit) {
  const microworld::PiezoGripperParams g;
  SafetyLimitParams lp;
  lp.finger_stiffness_N_m = g.finger_stiffness_N_m;
  const SafetyLimits limits(lp);
  const double width = 300e-6;
  microworld::PiezoGripperState s;
  s.free_opening_m = g.max_opening_m;
  double command = g.max_opening_m, peak = 0.0, force = 0.0;
  for (int i = 0; i < 5000; ++i) {  // 0.5 s at 10 kHz
    const double measured = force > 0.0 ? width : s.free_opening_m;
    command = limits.limit_opening_m(/*requested=*/0.0, measured, force, command);
    microworld::step_gripper(g, s, command, kDt);
    force = microworld::grip_force_N(g, s, width);
    peak = std::max(peak, force);
  }
  EXPECT_LE(peak, lp.grip_force_limit_N * (1 + 1e-9));
  EXPECT_GT(force, 0.99 * lp.grip_force_limit_N) << "it closes up to the limit: a firm grip";
  // Without the limit the same command squeezes with k w / 2 = 7.5 mN.
  EXPECT_NEAR(g.finger_stiffness_N_m * width / 2, 7.5e-3, 1e-12);
}

TEST(SafetyLimits, AStifferGripperThanModelledIsOpenedBackUnderTheLimit) {
  const SafetyLimits limits(SafetyLimitParams{});
  // The measured force is twice the limit: the command opens by 2 (F - F_max) / k at least.
  const double c = limits.limit_opening_m(0.0, 300e-6, 2e-3, 250e-6);
  EXPECT_NEAR(c, 250e-6 + 2 * 1e-3 / 50.0, 1e-12);
  // Out of contact, any opening is allowed.
  EXPECT_DOUBLE_EQ(limits.limit_opening_m(0.0, 600e-6, 0.0, 600e-6), 0.0);
  EXPECT_DOUBLE_EQ(limits.limit_opening_m(123e-6, 600e-6, 0.0, 600e-6), 123e-6);
}

TEST(SafetyLimits, OverTheContactLimitTheTargetGoesNoFurtherInButMayBackOff) {
  SafetyLimitParams lp;
  lp.floor_m = -1e-3;
  const SafetyLimits limits(lp);
  const Eigen::Vector3d measured(0, 0, 0);
  const Eigen::Vector3d push_back(0, 0, 3e-3);  // the substrate pushes the tool up: 3 mN
  Eigen::Vector3d target(10e-6, 0, -5e-6), v(1e-4, 0, -1e-3);
  limits.limit_target(target, v, measured, push_back);
  EXPECT_DOUBLE_EQ(target.z(), 0.0) << "no further down than where the tool is";
  EXPECT_DOUBLE_EQ(target.x(), 10e-6) << "sideways is free";
  EXPECT_DOUBLE_EQ(v.z(), 0.0);
  Eigen::Vector3d up(0, 0, 5e-6), vu(0, 0, 1e-4);
  limits.limit_target(up, vu, measured, push_back);
  EXPECT_DOUBLE_EQ(up.z(), 5e-6) << "backing off is free";
  Eigen::Vector3d below(0, 0, -2e-3), vb(0, 0, -1e-3);
  limits.limit_target(below, vb, measured, Eigen::Vector3d::Zero());
  EXPECT_DOUBLE_EQ(below.z(), -1e-3) << "never below the floor";
  EXPECT_DOUBLE_EQ(vb.z(), 0.0);
}

TEST(SafetyLimits, RejectsBadLimits) {
  for (double bad : {0.0, -1.0, double(std::numeric_limits<double>::quiet_NaN()),
                     double(std::numeric_limits<double>::infinity())}) {
    SafetyLimitParams p;
    p.grip_force_limit_N = bad;
    EXPECT_THROW(SafetyLimits{p}, InvalidParams);
    p = SafetyLimitParams{};
    p.contact_force_limit_N = bad;
    EXPECT_THROW(SafetyLimits{p}, InvalidParams);
  }
  SafetyLimitParams p;
  p.floor_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(SafetyLimits{p}, InvalidParams);
}

// Nothing of the slave moves without the deadman, the gripper included.
TEST(Teleoperation, TheGripperHoldsWithoutTheDeadmanWhateverTheConsoleOrTheTweezersSay) {
  Teleoperation t(TeleoperationParams{}, kDt, {0, 0, 0}, 600e-6);
  TeleoperationInput in;
  in.console.active = true;
  in.console.fresh = true;
  in.console.deadman = false;
  in.console.has_gripper = true;
  in.console.gripper_opening_m = 0.0;
  in.console.velocity_m_s = {1e-4, 0, 0};
  for (int i = 0; i < 100; ++i) t.tick(in);
  EXPECT_DOUBLE_EQ(t.output().gripper_opening_m, 600e-6);
  EXPECT_DOUBLE_EQ(t.output().slave_target_m.x(), 0.0);
  in.console.deadman = true;
  t.tick(in);
  EXPECT_DOUBLE_EQ(t.output().gripper_opening_m, 0.0);

  Teleoperation h(TeleoperationParams{}, kDt, {0, 0, 0}, 600e-6);
  TeleoperationInput hand;
  hand.deadman = false;
  hand.tweezers_opening_m = 2e-3;  // pinched: would command 120 um
  for (int i = 0; i < 100; ++i) h.tick(hand);
  EXPECT_DOUBLE_EQ(h.output().gripper_opening_m, 600e-6);
  hand.deadman = true;
  h.tick(hand);
  EXPECT_NEAR(h.output().gripper_opening_m, 120e-6, 1e-15);
}

TEST(Teleoperation, AHandPushingIntoAHeldContactDoesNotJumpTheSlaveWhenTheForceDrops) {
  Teleoperation t(TeleoperationParams{}, kDt, {0, 0, 0}, 600e-6);
  TeleoperationInput in;
  in.deadman = true;
  in.tweezers_opening_m = 10e-3;
  t.tick(in);                          // engaged at the origin
  in.contact_force_N = {-3e-3, 0, 0};  // a wall at +x pushes back with 3 mN
  for (int i = 1; i <= 100; ++i) {
    in.handle_m.x() = 1e-4 * i;  // the hand goes on into the wall: 10 mm -> 100 um of slave
    t.tick(in);
    EXPECT_LE(t.output().slave_target_m.x(), 0.0);
    EXPECT_TRUE(t.contact_limited());
  }
  in.contact_force_N.setZero();
  t.tick(in);
  EXPECT_LE(t.output().slave_target_m.x(), 1e-9) << "the hand's travel into the wall is not replayed";
}

}  // namespace
}  // namespace mc::teleop
