// The task object alone: skip() leaves the current step for the next one
// from where the stage is, whatever the task's status, on an ideal stage that follows the task's
// goal moves exactly (the platform's part is cell_cycle_test.cc's).
#include "microcobot/cell/assembly_task.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace mc::cell {
namespace {

using Step = AssemblyTask::Step;
using Status = AssemblyTask::Status;
using Autonomy = AssemblyTask::Autonomy;

// An ideal stage: the tip moves along the task's straight goal moves at their speed; the
// gripper closes on a 200 um pin (grip force once the command is below its width).
struct IdealStage {
  TaskSensors s;
  Eigen::Vector3d start_m{0.0, 0.0, 900e-6};
  IdealStage() {
    s.tip_m = start_m;
    s.opening_m = 600e-6;
  }
  // One 1 ms tick of `task`; returns the distance the tip moved.
  double tick(AssemblyTask& task) {
    const teleop::ConsoleInput& in = task.tick(s, 1e-3);
    const Eigen::Vector3d before = s.tip_m;
    if (in.deadman && in.has_goal) {
      const Eigen::Vector3d d = in.goal_m - s.tip_m;
      const double step = in.goal_speed_m_s * 1e-3;
      s.tip_m = d.norm() <= step ? in.goal_m : Eigen::Vector3d(s.tip_m + d * (step / d.norm()));
    }
    if (in.deadman && in.has_theta_goal) {  // the rotary axis, likewise
      const double d = in.theta_goal_rad - s.yaw_rad, step = in.theta_speed_rad_s * 1e-3;
      s.yaw_rad = std::abs(d) <= step ? in.theta_goal_rad : s.yaw_rad + std::copysign(step, d);
    }
    if (in.has_gripper) s.opening_m = std::max(200e-6, in.gripper_opening_m);
    s.grip_N = in.gripper_opening_m < 200e-6 ? 0.5e-3 : 0.0;
    return (s.tip_m - before).norm();
  }
  // Ticks until `step` is entered (or `max_s` of ticks).
  bool run_to(AssemblyTask& task, Step step, double max_s = 30.0) {
    for (int i = 0; i < static_cast<int>(max_s * 1e3); ++i) {
      if (task.step() == step) return true;
      tick(task);
    }
    return task.step() == step;
  }
};

AssemblyGoal skip_goal() {
  AssemblyGoal g;
  g.part_m = {-1e-3, 0.0};
  g.target_m = {1e-3, 0.2e-3};
  return g;
}

TEST(AssemblyTask, SkipGoesOnToTheNextStepFromWhereTheStageIs) {
  AssemblyTask task({}, skip_goal());
  IdealStage stage;
  for (int i = 0; i < 500; ++i) stage.tick(task);  // 0.5 s into the approach
  ASSERT_EQ(task.step(), Step::kApproach);
  const Eigen::Vector3d here = stage.s.tip_m;
  ASSERT_GT((here - stage.start_m).norm(), 50e-6) << "on its way";
  task.skip();
  EXPECT_EQ(task.step(), Step::kAlign);
  EXPECT_EQ(task.status(), Status::kRunning);
  // The alignment holds over the pin, going on there from where the stage was left: one tick's
  // travel at the travel speed, no jump.
  const double moved = stage.tick(task);
  EXPECT_LE(moved, AssemblyTaskParams{}.travel_speed_m_s * 1e-3 * 1.001);
  EXPECT_GT(moved, 0.0);
  // And it goes on to the grasp from there.
  EXPECT_TRUE(stage.run_to(task, Step::kGrasp));
}

TEST(AssemblyTask, APausedTaskSkipsIntoThePausedNextStepAndHolds) {
  AssemblyTask task({}, skip_goal());
  IdealStage stage;
  ASSERT_TRUE(stage.run_to(task, Step::kLift));
  task.pause();
  task.skip();
  EXPECT_EQ(task.step(), Step::kTransport);
  EXPECT_EQ(task.status(), Status::kPaused);
  for (int i = 0; i < 200; ++i) EXPECT_EQ(stage.tick(task), 0.0) << "holds while paused";
  task.resume();
  EXPECT_EQ(task.status(), Status::kRunning);
  EXPECT_GT(stage.tick(task), 0.0);
}

TEST(AssemblyTask, SkipLeavesAWaitingOrManualStepAndTheNextStepsAutonomyApplies) {
  AssemblyTask task({}, skip_goal());
  task.set_autonomy(Step::kApproach, Autonomy::kConfirm);
  task.set_autonomy(Step::kAlign, Autonomy::kManual);
  task.set_autonomy(Step::kDescend, Autonomy::kConfirm);
  IdealStage stage;
  stage.tick(task);
  ASSERT_EQ(task.status(), Status::kAwaitingConfirm);
  task.skip();  // not confirmed: skipped
  EXPECT_EQ(task.step(), Step::kAlign);
  EXPECT_EQ(task.status(), Status::kOperator) << "align is manual";
  EXPECT_FALSE(task.drives());
  task.skip();  // the operator says: the fingers are square already
  EXPECT_EQ(task.step(), Step::kDescend);
  EXPECT_EQ(task.status(), Status::kAwaitingConfirm) << "descend waits for its confirmation";
  EXPECT_EQ(stage.tick(task), 0.0);
}

TEST(AssemblyTask, SkippingIntoTheInsertionStartsAFreshSearchAndSkippingTheLastStepSucceeds) {
  AssemblyTask task({}, skip_goal());
  IdealStage stage;
  ASSERT_TRUE(stage.run_to(task, Step::kRotate));
  task.skip();
  EXPECT_EQ(task.step(), Step::kInsert);
  EXPECT_EQ(task.search_tries(), 0);
  task.skip();
  task.skip();
  EXPECT_EQ(task.step(), Step::kRetract);
  task.skip();
  EXPECT_EQ(task.step(), Step::kVerify);
  task.skip();
  EXPECT_EQ(task.step(), Step::kDone);
  EXPECT_EQ(task.status(), Status::kSucceeded);
  task.skip();  // finished: nothing
  EXPECT_EQ(task.status(), Status::kSucceeded);
  EXPECT_EQ(stage.tick(task), 0.0) << "a finished task holds";
}

// The last step looks at the pin (the cell's vision, TaskSensors::part_m): down in its bore, the
// task succeeds; still up (stuck to a finger, on the rim), it fails saying so; without vision the
// insertion's own evidence stands.
TEST(AssemblyTask, VerifyLooksAtThePinAndFailsATaskWhosePinIsNotDown) {
  const AssemblyGoal goal = skip_goal();
  const double inserted_z = 0.5 * goal.part_height_m - goal.hole_depth_m;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    double seen_z;
    Status expected;
  };
  for (const Case c :
       {Case{inserted_z + 0.3e-6, Status::kSucceeded}, Case{inserted_z + 150e-6, Status::kFailed},
        Case{0.5 * goal.part_height_m, Status::kFailed}, Case{nan, Status::kSucceeded}}) {
    AssemblyTask task({}, goal);
    IdealStage stage;
    ASSERT_TRUE(stage.run_to(task, Step::kRotate));
    task.skip();  // into the insertion, then past it: the ideal stage has no contact to end it
    task.skip();
    task.skip();
    ASSERT_EQ(task.step(), Step::kRetract);
    ASSERT_TRUE(stage.run_to(task, Step::kVerify));
    stage.s.part_m = {goal.target_m.x() + 1e-6, goal.target_m.y(), c.seen_z};
    for (int i = 0; i < 1000 && !task.finished(); ++i)
      EXPECT_EQ(stage.tick(task), 0.0) << "verify holds still";
    EXPECT_EQ(task.status(), c.expected) << "pin seen at " << c.seen_z * 1e6 << " um";
    if (c.expected == Status::kFailed) {
      EXPECT_EQ(task.step(), Step::kVerify);
      EXPECT_NE(std::string(task.failure()).find("not down in its bore"), std::string::npos)
          << task.failure();
    }
  }
}

}  // namespace
}  // namespace mc::cell

namespace mc::cell {
namespace {

// With the cell's camera (set_looks): the task holds for its look before the approach moves, then
// heads for the pin where it was seen; before the transport it holds for the look at the bore and
// carries the pin where the bore was seen; at the insertion's start it holds for the look at the
// pin in the fingers, then aims the pin, not the tool point, at the bore's axis.
TEST(AssemblyTask, WithACameraItHoldsForItsLooksAndGoesWhereThePinWasSeen) {
  AssemblyGoal g = skip_goal();
  g.target_yaw_rad = 0.3;
  AssemblyTask task({}, g);
  task.set_looks(true);
  IdealStage stage;
  for (int i = 0; i < 100; ++i) EXPECT_EQ(stage.tick(task), 0.0);  // 0.1 s: held, the deadman off
  EXPECT_EQ(task.status(), Status::kAwaitingLook);
  EXPECT_EQ(task.look_wanted(), AssemblyTask::Look::kSlot);
  EXPECT_FALSE(task.tick(stage.s, 1e-3).deadman);

  AssemblyTask::Sighting slot;
  slot.found = true;
  slot.part_m = {g.part_m.x() + 4e-6, g.part_m.y() - 3e-6, 300e-6};
  slot.yaw_rad = 0.02;
  task.see(slot);
  EXPECT_EQ(task.status(), Status::kRunning);
  EXPECT_EQ(task.look_wanted(), AssemblyTask::Look::kNone);
  ASSERT_TRUE(stage.run_to(task, Step::kGrasp));
  EXPECT_LT((stage.s.tip_m.head<2>() - slot.part_m.head<2>()).norm(), 1e-9) << "over the pin as seen";
  EXPECT_NEAR(stage.s.yaw_rad, 0.02, 1e-3) << "square with the pin as seen";

  // Before the transport moves: the bore, 9 um off its drawing.
  ASSERT_TRUE(stage.run_to(task, Step::kTransport));
  stage.tick(task);
  EXPECT_EQ(task.look_wanted(), AssemblyTask::Look::kBore);
  const Eigen::Vector2d drawn = g.target_m;
  AssemblyTask::Sighting bore;
  bore.found = true;
  bore.part_m << drawn + Eigen::Vector2d(6e-6, -7e-6), 0.0;
  task.see(bore);
  EXPECT_EQ(task.goal().target_m, bore.part_m.head<2>());
  ASSERT_TRUE(stage.run_to(task, Step::kInsert));
  stage.tick(task);
  EXPECT_EQ(task.look_wanted(), AssemblyTask::Look::kHeld);
  const Eigen::Vector3d tip = stage.s.tip_m;
  const Eigen::Vector2d ey(-std::sin(stage.s.yaw_rad), std::cos(stage.s.yaw_rad));
  AssemblyTask::Sighting held;
  held.found = true;
  held.part_m << tip.head<2>() + 5e-6 * ey, tip.z();
  task.see(held);
  EXPECT_NEAR(task.held_offset_m(), 5e-6, 1e-12);
  const teleop::ConsoleInput& in = task.tick(stage.s, 1e-3);
  ASSERT_TRUE(in.deadman && in.has_goal);
  EXPECT_LT((in.goal_m.head<2>() - (bore.part_m.head<2>() - 5e-6 * ey)).norm(), 1e-12)
      << "the pin on the axis of the bore as seen";
}

// With the visual servo (set_looks(true, true)): at the insertion's start the task holds for the
// align look (the pin against its bore, one camera pose), moves the tool by minus the error seen at
// the carrying height, looks again, and descends once the servo says converged; the pin's offset
// in the fingers is in that error, so no held look is taken.
TEST(AssemblyTask, WithTheServoItMovesByTheErrorSeenAndLooksAgainUntilConverged) {
  const AssemblyGoal g = skip_goal();
  AssemblyTask task({}, g);
  task.set_looks(true, true);
  IdealStage stage;
  const auto look = [&](AssemblyTask::Look want) {
    for (int i = 0; i < 20000 && task.look_wanted() == AssemblyTask::Look::kNone; ++i) stage.tick(task);
    return task.look_wanted() == want;
  };
  ASSERT_TRUE(look(AssemblyTask::Look::kSlot));
  task.see({});
  ASSERT_TRUE(look(AssemblyTask::Look::kBore));
  AssemblyTask::Sighting bore;
  bore.found = true;
  bore.part_m << g.target_m + Eigen::Vector2d(6e-6, -7e-6), 0.0;
  task.see(bore);
  ASSERT_TRUE(look(AssemblyTask::Look::kAlign));
  EXPECT_EQ(task.step(), Step::kInsert);
  const Eigen::Vector3d over = stage.s.tip_m;
  EXPECT_LT((over.head<2>() - bore.part_m.head<2>()).norm(), 1e-9) << "over the bore as seen";
  AssemblyTask::Sighting off;
  off.found = true;
  off.error_m = {3e-6, -4e-6};  // the pin seen 5 um off the bore's axis
  task.see(off);
  ASSERT_TRUE(look(AssemblyTask::Look::kAlign)) << "looks again once the correction is made";
  EXPECT_LT((stage.s.tip_m.head<2>() - (over.head<2>() - off.error_m)).norm(), 1e-9);
  EXPECT_NEAR(stage.s.tip_m.z(), over.z(), 1e-9) << "at the carrying height";
  EXPECT_EQ(task.align_looks(), 1);
  AssemblyTask::Sighting there;
  there.found = true;
  there.error_m = {0.1e-6, 0.05e-6};
  there.converged = true;
  task.see(there);
  const teleop::ConsoleInput& in = task.tick(stage.s, 1e-3);
  EXPECT_EQ(task.look_wanted(), AssemblyTask::Look::kNone);
  ASSERT_TRUE(in.deadman && in.has_goal);
  EXPECT_LT((in.goal_m.head<2>() - (over.head<2>() - off.error_m)).norm(), 1e-12)
      << "descends where it aimed";
  EXPECT_LT(in.goal_m.z(), over.z()) << "down";
  EXPECT_EQ(task.align_looks(), 2);
  EXPECT_TRUE(std::isnan(task.held_offset_m())) << "no held look";
}

// The servo's looks are bounded (align_max_looks): an error that never converges (a stage whose
// moves miss) is corrected for the last time and the descent goes on, the search round that point;
// an align look that finds nothing descends over the bore as seen.
TEST(AssemblyTask, TheServoGivesUpAfterItsLooksAndANothingSeenDescends) {
  const AssemblyGoal g = skip_goal();
  AssemblyTaskParams p;
  p.align_max_looks = 3;
  for (const bool seen : {true, false}) {
    AssemblyTask task(p, g);
    task.set_looks(true, true);
    IdealStage stage;
    int aligns = 0;
    for (int i = 0; i < 60000 && task.step() != Step::kRelease; ++i) {
      switch (task.look_wanted()) {
        case AssemblyTask::Look::kNone:
          stage.tick(task);
          // Down in the bore (its rim at the grasp height, 400 um; its floor 300 um below).
          if (task.step() == Step::kInsert && stage.s.tip_m.z() < 200e-6) stage.s.contact_N.z() = 1e-3;
          break;
        case AssemblyTask::Look::kAlign: {
          ++aligns;
          AssemblyTask::Sighting s;
          s.found = seen;
          s.error_m = {1e-6, 0.0};  // never converges
          task.see(s);
          break;
        }
        default:
          task.see({});
      }
    }
    ASSERT_EQ(task.step(), Step::kRelease) << (seen ? "seen: " : "not seen: ") << task.failure();
    EXPECT_EQ(aligns, seen ? 3 : 1);
    EXPECT_NEAR(task.align_aim_m().x(), seen ? -3e-6 : 0.0, 1e-12);
  }
}

// A look that finds nothing leaves the task as without a camera: the slot's nominal position.
TEST(AssemblyTask, ALookThatFindsNothingLeavesTheNominalSlot) {
  const AssemblyGoal g = skip_goal();
  AssemblyTask task({}, g);
  task.set_looks(true);
  IdealStage stage;
  stage.tick(task);
  ASSERT_EQ(task.look_wanted(), AssemblyTask::Look::kSlot);
  task.see({});
  ASSERT_TRUE(stage.run_to(task, Step::kGrasp));
  EXPECT_LT((stage.s.tip_m.head<2>() - g.part_m).norm(), 1e-9);
}

// An assisted move (a step done by the operator under shared control): the task
// hands the stage to the operator's master, holds a guide at the step's goal x, y and a height stop
// at its z, and goes on by itself once the tool has been at the goal for settle_s; the next step is
// the robot's again, from where the stage is.
TEST(AssemblyTask, AnAssistedMoveGuidesTheOperatorToItsGoalAndGoesOnOnceThere) {
  AssemblyTask task({}, skip_goal());
  task.set_autonomy(Step::kTransport, Autonomy::kAssisted);
  IdealStage stage;
  ASSERT_TRUE(stage.run_to(task, Step::kTransport));
  EXPECT_EQ(task.status(), Status::kAssisted);
  EXPECT_FALSE(task.drives());
  EXPECT_TRUE(task.operator_drives());
  const Eigen::Vector3d lifted = stage.s.tip_m;
  // The operator's master drives: the task sends no move, and holds its fixtures.
  for (int i = 0; i < 100; ++i) EXPECT_EQ(stage.tick(task), 0.0);
  const teleop::FixtureSet& f = task.fixtures();
  EXPECT_EQ(f.level, 1.0);
  EXPECT_TRUE(f.guide && f.height && !f.funnel);
  EXPECT_EQ(f.guide_xy_m, skip_goal().target_m) << "the guide on the bore";
  EXPECT_TRUE(f.path);
  EXPECT_EQ(f.path_from_xy_m, lifted.head<2>()) << "along the path from where the transport began";
  EXPECT_DOUBLE_EQ(f.height_z_m, lifted.z()) << "the stop at the carrying height";
  // Near the goal is not there: the step waits.
  stage.s.tip_m = Eigen::Vector3d(f.guide_xy_m.x() + 3e-6, f.guide_xy_m.y(), f.height_z_m);
  for (int i = 0; i < 200; ++i) stage.tick(task);
  EXPECT_EQ(task.step(), Step::kTransport);
  // At the goal (what the guide makes of an operator within its capture) for settle_s: the rotation.
  stage.s.tip_m = Eigen::Vector3d(f.guide_xy_m.x(), f.guide_xy_m.y(), task.fixtures().height_z_m);
  for (int i = 0; i < 49 && task.step() == Step::kTransport; ++i) stage.tick(task);
  EXPECT_EQ(task.step(), Step::kTransport) << "held 49 ms of the 50";
  stage.tick(task);
  stage.tick(task);
  EXPECT_EQ(task.step(), Step::kRotate);
  EXPECT_EQ(task.status(), Status::kRunning);
  EXPECT_TRUE(task.drives());
  EXPECT_EQ(task.fixtures().level, 0.0) << "no guidance once the robot drives";
  EXPECT_TRUE(stage.run_to(task, Step::kInsert)) << "and the robot turns the pin and inserts from there";
}

// An assisted turn: the guide and the height stop hold the carried pin over its bore while the
// operator turns the dial into the yaw stop, at the bore's square yaw nearest where the turn began;
// the task goes on once the fingers have been there for settle_s.
TEST(AssemblyTask, AnAssistedTurnHoldsAYawStopAtTheSquaresYawAndGoesOnOnceTurned) {
  AssemblyGoal g = skip_goal();
  g.target_yaw_rad = 0.3;
  AssemblyTask task({}, g);
  task.set_autonomy(Step::kRotate, Autonomy::kAssisted);
  IdealStage stage;
  ASSERT_TRUE(stage.run_to(task, Step::kRotate));
  ASSERT_EQ(task.status(), Status::kAssisted);
  stage.tick(task);
  const teleop::FixtureSet& f = task.fixtures();
  EXPECT_TRUE(f.yaw && f.guide && f.height);
  EXPECT_NEAR(f.yaw_rad, 0.3, 1e-12) << "the bore's yaw, nearest where the turn began";
  EXPECT_EQ(f.guide_xy_m, g.target_m);
  // Turned near it, not within yaw_tolerance_rad: the step waits.
  stage.s.yaw_rad = 0.3 + 2e-3;
  for (int i = 0; i < 200; ++i) stage.tick(task);
  EXPECT_EQ(task.step(), Step::kRotate);
  stage.s.yaw_rad = 0.3;  // what the stop makes of a dial within its capture
  for (int i = 0; i < 60; ++i) stage.tick(task);
  EXPECT_EQ(task.step(), Step::kInsert);
  EXPECT_FALSE(task.fixtures().yaw) << "no stop once the robot drives";
}

TEST(AssemblyTask, AnAssistedStepCanBeTakenOverHandedBackOrIsTheOperatorsWhenNotAMove) {
  AssemblyTask task({}, skip_goal());
  task.set_autonomy(Step::kApproach, Autonomy::kAssisted);
  task.set_autonomy(Step::kVerify, Autonomy::kAssisted);  // not a move: the operator's
  IdealStage stage;
  stage.tick(task);
  ASSERT_EQ(task.status(), Status::kAssisted);
  task.take_over();
  stage.tick(task);
  EXPECT_EQ(task.status(), Status::kOperator);
  EXPECT_EQ(task.fixtures().level, 0.0) << "taken over: no guidance";
  task.hand_back(false);
  EXPECT_EQ(task.status(), Status::kRunning) << "handed back: the robot does the approach";
  EXPECT_TRUE(stage.run_to(task, Step::kAlign));
  while (task.step() != Step::kVerify) task.skip();
  EXPECT_EQ(task.status(), Status::kOperator);
  EXPECT_TRUE(AssemblyTask::assistable(Step::kRetract));
  EXPECT_TRUE(AssemblyTask::assistable(Step::kInsert));
  EXPECT_TRUE(AssemblyTask::assistable(Step::kRotate));
  EXPECT_TRUE(AssemblyTask::assistable(Step::kAlign));
  EXPECT_FALSE(AssemblyTask::assistable(Step::kVerify));
  EXPECT_EQ(AssemblyTask::name(Status::kAssisted), "assisted");
  EXPECT_EQ(AssemblyTask::name(Autonomy::kAssisted), "assisted");
}

// An assisted grasp: the operator closes the fingers (the console's slider), the guide and the
// stop hold the tool over the pin; once the grip holds, the robot lifts with the operator's
// gripper command, never its own open one (a hand-back that opened the fingers would drop the pin).
TEST(AssemblyTask, AfterAnAssistedGraspTheRobotLiftsWithTheOperatorsGripNotItsOwnOpening) {
  AssemblyTask task({}, skip_goal());
  task.set_autonomy(Step::kGrasp, Autonomy::kAssisted);
  IdealStage stage;
  ASSERT_TRUE(stage.run_to(task, Step::kGrasp));
  ASSERT_EQ(task.status(), Status::kAssisted);
  const Eigen::Vector3d at = stage.s.tip_m;
  stage.tick(task);  // the step's first tick sets its fixtures
  EXPECT_EQ(task.fixtures().guide_xy_m, skip_goal().part_m);
  EXPECT_TRUE(task.fixtures().height);
  EXPECT_DOUBLE_EQ(task.fixtures().height_z_m, at.z()) << "the grasp height the descent reached";
  // The operator's slider from wide open to 150 um at 1 mm/s.
  stage.s.gripper_command_m = 600e-6;
  for (int i = 0; i < 1000 && task.step() == Step::kGrasp; ++i) {
    stage.s.gripper_command_m = std::max(150e-6, stage.s.gripper_command_m - 1e-6);
    stage.tick(task);
  }
  ASSERT_EQ(task.step(), Step::kLift);
  EXPECT_EQ(task.status(), Status::kRunning);
  stage.s.gripper_command_m = std::numeric_limits<double>::quiet_NaN();  // the robot's command again
  for (int i = 0; i < 3000 && task.step() != Step::kTransport; ++i) {
    stage.tick(task);
    ASSERT_GT(stage.s.grip_N, 0.0) << "the fingers opened at " << i << " ms of the lift";
  }
  EXPECT_EQ(task.step(), Step::kTransport);
  EXPECT_GT(stage.s.tip_m.z(), at.z() + 100e-6) << "lifted";
}

// An assisted insertion: the guide on the bore's axis and the funnel round its rim; judged at the
// first contact: half down in the bore, the release; on the rim, the robot's search takes over.
TEST(AssemblyTask, AnAssistedInsertionHoldsTheFunnelAndIsJudgedAtItsFirstContact) {
  for (const bool on_rim : {false, true}) {
    AssemblyTask task({}, skip_goal());
    task.set_autonomy(Step::kInsert, Autonomy::kAssisted);
    IdealStage stage;
    ASSERT_TRUE(stage.run_to(task, Step::kLift));
    const double rim_z = stage.s.tip_m.z();  // where the grasp held the pin standing on the surface
    ASSERT_TRUE(stage.run_to(task, Step::kInsert));
    ASSERT_EQ(task.status(), Status::kAssisted);
    stage.tick(task);
    const teleop::FixtureSet& f = task.fixtures();
    EXPECT_TRUE(f.guide && f.funnel && !f.height);
    EXPECT_EQ(f.guide_xy_m, skip_goal().target_m);
    EXPECT_DOUBLE_EQ(f.rim_z_m, rim_z);
    EXPECT_DOUBLE_EQ(f.funnel_radius_m, 0.5 * skip_goal().clearance_m);
    for (int i = 0; i < 100; ++i) stage.tick(task);
    EXPECT_EQ(task.step(), Step::kInsert) << "no contact yet";
    stage.s.contact_N = {0.0, 0.0, 0.2e-3};
    stage.s.tip_m.z() = on_rim ? rim_z : rim_z - 0.9 * skip_goal().hole_depth_m;
    stage.tick(task);
    EXPECT_DOUBLE_EQ(task.insert_contact_z_m(), stage.s.tip_m.z());
    if (on_rim) {
      EXPECT_EQ(task.step(), Step::kInsert);
      EXPECT_EQ(task.status(), Status::kRunning) << "the robot's search from the rim";
      EXPECT_EQ(task.search_tries(), 1);
      EXPECT_EQ(task.fixtures().level, 0.0);
      stage.s.contact_N.setZero();
      EXPECT_GT(stage.tick(task), 0.0) << "up from the rim, driven by the robot";
    } else {
      EXPECT_EQ(task.step(), Step::kRelease) << "at the first contact";
      EXPECT_EQ(task.search_tries(), 0);
    }
  }
}

}  // namespace
}  // namespace mc::cell
