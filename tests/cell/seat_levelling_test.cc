// The seat levelled before the insertion, with the part on the parallel positioner (the thesis's
// assembly): the procedure's geometry on its own, then batches on tilted seats with and without it.
#include "microcobot/cell/seat_levelling.h"

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "microcobot/cell/cell_run.h"
#include "microcobot/core/error.h"
#include "microcobot/devices/carried_seat.h"

namespace mc::cell {
namespace {

platform::PlatformConfig on_positioner() {
  platform::PlatformConfig c;
  c.positioner = "parallel";
  return c;
}

/// The seat z = a x + b y + c under a stage that goes where it is told at the speed it is told,
/// the held part's bottom `offset` under the tool, pushed up in the fingers by `slip` as each touch
/// begins (after the part was a micrometre off the seat).
struct PlaneSeat {
  double a, b, c;
  double offset = 400e-6, slip = 0.2e-6;
  bool armed = true;  // the part has been off the seat since its last touch
  double z(const Eigen::Vector2d& xy) const { return a * xy.x() + b * xy.y() + c; }
  void step(const teleop::ConsoleInput& in, TaskSensors& s) {
    if (in.has_goal) {
      const Eigen::Vector3d step = in.goal_m - s.tip_m;
      const double most = in.goal_speed_m_s * 1e-3;
      s.tip_m += step.norm() > most ? Eigen::Vector3d(step.normalized() * most) : step;
    }
    const double under = z(s.tip_m.head<2>()) + offset - s.tip_m.z();
    if (under > 0.0 && armed) {  // a touch begins: the part slides up a little
      offset -= slip;
      armed = false;
    }
    if (under < -1e-6) armed = true;
    const double press = z(s.tip_m.head<2>()) + offset - s.tip_m.z();
    s.contact_N = {0.0, 0.0, press > 0.0 ? 1e5 * press : 0.0};
  }
};

TEST(SeatLevelling, FourTouchesOnATiltedSeatMeasureItsTiltDespiteThePartSlippingInTheFingers) {
  PlaneSeat seat{0.02, -0.015, -3e-6};
  const Eigen::Vector2d bore(1.5e-3, 0.2e-3);
  SeatLevelling l(SeatLevellingParams{}, bore, 400e-6);
  TaskSensors s;
  s.tip_m = {1.5e-3, 0.2e-3, 800e-6};
  s.gripper_command_m = 150e-6;
  for (int tick = 0; tick < 400000 && !l.wants_move() && !l.finished(); ++tick) {
    const teleop::ConsoleInput& in = l.tick(s, 1e-3);
    ASSERT_TRUE(in.active && in.fresh && in.deadman);  // nothing moves without the deadman
    ASSERT_TRUE(in.has_gripper);                       // the grip kept as the task left it
    ASSERT_EQ(in.gripper_opening_m, 150e-6);
    seat.step(in, s);
  }
  ASSERT_TRUE(l.wants_move()) << l.failure();
  EXPECT_EQ(l.rounds(), 1);
  // Four touches, each slipping the part 0.2 um: without the drift taken out the slope would be
  // off by about 0.4 um over the probe's 0.5 mm triangle (0.8 mrad).
  const Eigen::Vector3d n = Eigen::Vector3d(-seat.a, -seat.b, 1.0).normalized();
  EXPECT_LT((l.normal() - n).norm(), 1e-4);
  EXPECT_NEAR(l.tilt_before_rad(), std::acos(n.z()), 1e-4);
  // The part's bottom over the bore: where the tool meets the seat now.
  EXPECT_NEAR(l.contact_height_m(), seat.z(bore) + seat.offset, 0.1e-6);
  // The plate's goal turns the measured normal to the vertical about the plate's centre.
  motion::PlatformTransform plate;
  plate.R = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  plate.d = {0.1e-3, -0.2e-3, 0.0};
  const motion::PlatformTransform goal = l.level_goal(plate);
  EXPECT_LT((goal.R * plate.R.transpose() * l.normal() - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  EXPECT_EQ(goal.d, plate.d);
  // The seat on the plate as measured: the measured normal in the world, the plate's heading.
  const motion::PlatformTransform m = l.seat_on_plate(plate);
  const Eigen::Matrix3d seat_R = plate.R * m.R;
  EXPECT_LT((seat_R.col(2) - l.normal()).norm(), 1e-12);
  EXPECT_NEAR(std::atan2(seat_R(1, 0), seat_R(0, 0)), 0.1, 1e-3);
  EXPECT_EQ(m.d, Eigen::Vector3d::Zero());
  // Moved: a second round on the seat now level (the plate's move, done here on the fake seat).
  l.move_started(true);
  l.moved(true);
  seat.a = seat.b = 0.0;
  for (int tick = 0; tick < 400000 && !l.finished(); ++tick) seat.step(l.tick(s, 1e-3), s);
  EXPECT_EQ(l.phase(), SeatLevelling::Phase::kDone) << l.failure();
  EXPECT_EQ(l.rounds(), 2);
  EXPECT_LT(l.tilt_rad(), SeatLevellingParams{}.tolerance_rad);
  EXPECT_LT((s.tip_m - Eigen::Vector3d(1.5e-3, 0.2e-3, 800e-6)).norm(), 1e-6);  // back where it began
}

TEST(SeatLevelling, AMoveThatStopsShortOrASeatOutOfReachFailsWithTheReason) {
  PlaneSeat seat{0.02, 0.0, 0.0};
  SeatLevelling l(SeatLevellingParams{}, {1.5e-3, 0.0}, 400e-6);
  TaskSensors s;
  s.tip_m = {1.5e-3, 0.0, 800e-6};
  for (int tick = 0; tick < 400000 && !l.wants_move(); ++tick) seat.step(l.tick(s, 1e-3), s);
  l.move_started(true);
  l.moved(false);
  EXPECT_EQ(l.phase(), SeatLevelling::Phase::kFailed);
  EXPECT_STREQ(l.failure(), "the plate's levelling move stopped short");
  EXPECT_FALSE(l.tick(s, 1e-3).deadman);  // the platform holds
  // No seat under the part within the descent's travel.
  SeatLevelling far(SeatLevellingParams{}, {1.5e-3, 0.0}, 400e-6);
  PlaneSeat gone{0.0, 0.0, -2e-3};
  s.tip_m = {1.5e-3, 0.0, 800e-6};
  for (int tick = 0; tick < 400000 && !far.finished(); ++tick) gone.step(far.tick(s, 1e-3), s);
  EXPECT_STREQ(far.failure(), "no touch of the seat within level_seat.max_travel_m");
}

TEST(SeatLevelling, BadParametersAreRefusedWithTheKeyNamed) {
  SeatLevellingParams p;
  p.mode = "sometimes";
  EXPECT_THROW(p.validate(), InvalidParams);
  p = {};
  p.tolerance_rad = 0.0;
  EXPECT_THROW(p.validate(), InvalidParams);
  p = {};
  p.max_rounds = 0;
  EXPECT_THROW(p.validate(), InvalidParams);
}

TEST(SeatLevelling, OnTiltedSeatsTheCellLevelsEachBeforeItsInsertionAndThePartsGoInThatWouldJamOtherwise) {
  // Parts on the parallel positioner, each seat tilted up to 2 deg on its plate; seed 23 is not
  // the seed the procedure's speeds were chosen on (5; docs/cell.md).
  AssemblyBatchParams scene;
  scene.parts = 3;
  scene.seed = 23;
  scene.max_seat_tilt_rad = 0.035;
  const auto jobs = assembly_jobs(scene);
  CellRunParams p;
  int levelled_in = 0, unlevelled_in = 0;
  for (const AssemblyJob& job : jobs) {
    CellCycle c(job, p, on_positioner());
    c.run_to_end();
    const CycleResult r = c.result();
    const double truth = c.platform().simulated_gripper()->seat().tilt_rad();
    std::printf("part %d levelled: %s; tilt %.4f -> %.5f rad measured, %.5f true; %d rounds, %.1f s\n",
                r.index, r.verdict.c_str(), r.seat_tilt_before_rad, r.seat_tilt_after_rad, truth,
                r.level_rounds, r.level_s);
    EXPECT_TRUE(r.seat_levelled) << r.verdict;
    EXPECT_LT(truth, 0.5e-3);  // under a fortieth of the tightest fit's wedge angle
    EXPECT_TRUE(r.ended_holding);
    EXPECT_EQ(r.grip_violations + r.contact_violations, 0);
    levelled_in += r.success ? 1 : 0;
    // The same part with the seat left as it is.
    CellRunParams off = p;
    off.level_seat.mode = "off";
    const CycleResult o = run_cycle(job, off, on_positioner());
    std::printf("part %d as it is: %s\n", o.index, o.verdict.c_str());
    unlevelled_in += o.success ? 1 : 0;
  }
  EXPECT_EQ(levelled_in, 3);
  EXPECT_LT(unlevelled_in, levelled_in);
}

TEST(SeatLevelling, OnIsRefusedWithoutAParallelPositioner) {
  AssemblyBatchParams scene;
  scene.parts = 1;
  const auto jobs = assembly_jobs(scene);
  CellRunParams p;
  p.level_seat.mode = "on";
  EXPECT_THROW(CellCycle(jobs[0], p, platform::PlatformConfig{}), InvalidParams);
}

}  // namespace
}  // namespace mc::cell
