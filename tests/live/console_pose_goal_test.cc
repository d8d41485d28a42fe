// The console's go-to pose, planned on the server's side: what each command of the controlling
// client asks of the loop, against the kinematics (motion::check_move) and what the loop published.
#include "microcobot/live/console_pose_goal.h"

#include <gtest/gtest.h>

#include "microcobot/motion/pose.h"

namespace mc::live {
namespace {

ConsoleCommand goal_command(const std::array<double, 6>& goal, bool deadman = true) {
  ConsoleCommand c;
  c.deadman = deadman;
  c.has_pose_goal = true;
  c.pose_goal = goal;
  return c;
}

TEST(ConsolePoseGoal, AReachableGoalIsPlannedOnceFromWhereTheLegsHold) {
  ConsolePoseGoal planner(motion::ParallelGeometryParams{});
  const std::array<double, 6> goal{100e-6, 0, 50e-6, 0, 0.01, 0};
  ConsolePoseView v;  // at home, nothing handled yet
  v.reference.d = Eigen::Vector3d(-20e-6, 0, 0);
  const auto first = planner.on_command(goal_command(goal), v);
  ASSERT_TRUE(first.push) << first.refusal;
  ASSERT_TRUE(first.push->trajectory);
  EXPECT_EQ(first.push->seq, 1u);
  EXPECT_EQ(first.push->trajectory->start().d, v.reference.d);
  EXPECT_TRUE(first.push->trajectory->goal().R.isApprox(motion::smarpod_rotation(0, 0.01, 0), 1e-15));
  EXPECT_DOUBLE_EQ(first.push->trajectory->goal().d.x(), 100e-6);
  // Until the loop takes it, and while it runs towards this goal, the same command asks nothing.
  EXPECT_FALSE(planner.on_command(goal_command(goal), v).push);
  v.handled_seq = 1;
  v.moving = true;
  EXPECT_FALSE(planner.on_command(goal_command(goal), v).push);
  // Arrived: nothing more.
  v.moving = false;
  v.reference = pose_goal_transform(goal_command(goal));
  EXPECT_FALSE(planner.on_command(goal_command(goal), v).push);
}

TEST(ConsolePoseGoal, WithoutTheDeadmanNothingIsPlannedAndWhenItIsDroppedTheRestIsPlannedFromThere) {
  ConsolePoseGoal planner(motion::ParallelGeometryParams{});
  const std::array<double, 6> goal{0, 200e-6, 0, 0, 0, 0.02};
  ConsolePoseView v;
  EXPECT_FALSE(planner.on_command(goal_command(goal, false), v).push);
  ASSERT_TRUE(planner.on_command(goal_command(goal), v).push);
  // The deadman was released mid-way: the loop dropped nothing, the platform held at 80 um.
  v.handled_seq = 1;
  v.reference.d = Eigen::Vector3d(0, 80e-6, 0);
  const auto rest = planner.on_command(goal_command(goal), v);
  ASSERT_TRUE(rest.push && rest.push->trajectory);
  EXPECT_EQ(rest.push->seq, 2u);
  EXPECT_EQ(rest.push->trajectory->start().d, v.reference.d);
}

TEST(ConsolePoseGoal, AnotherGoalStopsTheMoveFirstAndNoGoalStopsIt) {
  ConsolePoseGoal planner(motion::ParallelGeometryParams{});
  ConsolePoseView v;
  ASSERT_TRUE(planner.on_command(goal_command({100e-6, 0, 0, 0, 0, 0}), v).push);
  v.handled_seq = 1;
  v.moving = true;
  const auto stop = planner.on_command(goal_command({-100e-6, 0, 0, 0, 0, 0}), v);
  ASSERT_TRUE(stop.push);
  EXPECT_FALSE(stop.push->trajectory) << "a stop, not a move from a pose the legs are leaving";
  v.handled_seq = 2;
  v.moving = false;
  v.reference.d = Eigen::Vector3d(40e-6, 0, 0);
  const auto next = planner.on_command(goal_command({-100e-6, 0, 0, 0, 0, 0}), v);
  ASSERT_TRUE(next.push && next.push->trajectory);
  EXPECT_EQ(next.push->trajectory->start().d, v.reference.d);
  // The page stops sending the goal: the move under way ends.
  v.handled_seq = 3;
  v.moving = true;
  const auto cancelled = planner.on_command(ConsoleCommand{}, v);
  ASSERT_TRUE(cancelled.push);
  EXPECT_FALSE(cancelled.push->trajectory);
}

TEST(ConsolePoseGoal, AGoalOutOfReachIsRefusedOnceWithItsReasonAndNothingIsSent) {
  ConsolePoseGoal planner(motion::ParallelGeometryParams{});
  ConsolePoseView v;
  const auto refused = planner.on_command(goal_command({0.02, 0, 0, 0, 0, 0}), v);
  EXPECT_FALSE(refused.push);
  EXPECT_NE(refused.refusal.find("unreachable"), std::string::npos) << refused.refusal;
  EXPECT_EQ(refused.refusal.find('\n'), std::string::npos);
  const auto again = planner.on_command(goal_command({0.02, 0, 0, 0, 0, 0}), v);
  EXPECT_FALSE(again.push);
  EXPECT_TRUE(again.refusal.empty()) << "told once per goal, not at the command rate";
  // Goals of any size are refused at once, by the goal's own check (no path sampled to them).
  for (const double huge : {1e3, 1e300}) {
    const auto far = planner.on_command(goal_command({huge, 0, 0, 0, 0, huge}), v);
    EXPECT_FALSE(far.push);
    EXPECT_NE(far.refusal.find("unreachable"), std::string::npos) << far.refusal;
  }
  // A push the ring refused is planned again with the next command.
  const auto planned = planner.on_command(goal_command({1e-4, 0, 0, 0, 0, 0}), v);
  ASSERT_TRUE(planned.push);
  planner.not_sent();
  const auto retried = planner.on_command(goal_command({1e-4, 0, 0, 0, 0, 0}), v);
  ASSERT_TRUE(retried.push && retried.push->trajectory);
  EXPECT_EQ(retried.push->seq, planned.push->seq);
}

TEST(ConsolePoseGoal, AGoalThatBringsTheSeatOntoTheFingerTipsIsRefusedWithTheGapItWouldLeave) {
  ConsolePoseGoal planner(motion::ParallelGeometryParams{});
  ConsolePoseView v;
  v.tips_m = Eigen::Vector3d(-1.5e-3, 0, 60e-6);  // 60 um over the seat at home
  v.tip_floor_m = 10e-6;
  const auto refused = planner.on_command(goal_command({0, 0, 100e-6, 0, 0, 0}), v);
  EXPECT_FALSE(refused.push);
  EXPECT_NE(refused.refusal.find("within 0.0 um of the finger tips (their floor: 10 um)"), std::string::npos)
      << refused.refusal;
  // A tilt that swings the seat's edge under the tips up into them: refused along the way.
  const auto tilted = planner.on_command(goal_command({0, 0, 0, 0, 0.05, 0}), v);  // ry 2.9 deg
  EXPECT_FALSE(tilted.push);
  EXPECT_NE(tilted.refusal.find("finger tips"), std::string::npos) << tilted.refusal;
  // Up to the floor and no further is planned.
  const auto up = planner.on_command(goal_command({0, 0, 49e-6, 0, 0, 0}), v);
  ASSERT_TRUE(up.push) << up.refusal;
}

}  // namespace
}  // namespace mc::live
