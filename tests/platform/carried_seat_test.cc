// The thesis's assembly (`positioner: parallel`): the substrate, the part on it and its hole ride on
// the parallel positioner's top plate, seen by the gripper, the telemetry and the camera where the
// plate takes them; a move that brings the seat onto the finger tips stops at their floor or at the
// contact limit.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "microcobot/devices/carried_seat.h"
#include "microcobot/motion/pose.h"
#include "microcobot/platform/camera_scene.h"
#include "microcobot/platform/platform.h"

namespace mc::platform {
namespace {

using motion::PlatformTransform;
using motion::SmarPodPose;
constexpr double kSeatDeg = std::numbers::pi / 180.0;

void drive_with_deadman(Platform& p, bool deadman) {
  teleop::ConsoleInput in;
  in.active = true;
  in.fresh = true;
  in.deadman = deadman;
  in.goal_m = {p.config().stage.home_x_m, p.config().stage.home_y_m, p.config().stage.home_z_m};
  p.set_console_input(in);
}

bool start_plate_move(Platform& p, const SmarPodPose& goal) {
  motion::PoseTrajectory t(p.positioner()->reference_pose(), motion::to_transform(goal),
                           p.config().parallel_positioner.move);
  const motion::MoveCheck c = motion::check_move(p.positioner()->kinematics(), t);
  EXPECT_TRUE(c.ok) << c.reason;
  return p.start_pose_move(t);
}

// Runs until the positioner is at rest (at most `max_s`).
void settle_plate(Platform& p, double max_s) {
  const auto ticks = static_cast<int>(max_s / p.config().loop.period_s());
  for (int i = 0; i < ticks / 100 && !p.positioner()->at_rest(); ++i) p.loop().run_for(100);
}

const devices::SimulatedGripper& seat_gripper(const Platform& p) { return *p.simulation().gripper; }

TEST(CarriedSeat, MapsPointsBothWaysAndReadsTheHeadingAndTheTilt) {
  const devices::CarriedSeat seat{
      motion::to_transform(SmarPodPose{1e-3, -2e-3, 0.5e-3, 2 * kSeatDeg, -3 * kSeatDeg, 10 * kSeatDeg})};
  const Eigen::Vector3d p(0.3e-3, -0.1e-3, 0.2e-3);
  EXPECT_LT((seat.to_world(seat.to_seat(p)) - p).norm(), 1e-18);
  EXPECT_LT((seat.to_world(p) - (seat.T.R * p + seat.T.d)).norm(), 1e-18);
  EXPECT_NEAR(seat.yaw_rad(), 10 * kSeatDeg, 1e-15);  // R = Rz Ry Rx: the x axis' heading is rz
  EXPECT_NEAR(seat.tilt_rad(), std::acos(std::cos(2 * kSeatDeg) * std::cos(3 * kSeatDeg)), 1e-12);
  EXPECT_EQ(devices::CarriedSeat{}.tilt_rad(), 0.0);
}

TEST(CarriedSeat, ThePartMovesAndTurnsWithThePositionersTopPlate) {
  PlatformConfig c;
  c.positioner = "parallel";
  Platform p{c};
  p.loop().run_for(2000);  // the legs power up
  const Eigen::Vector3d part0 = seat_gripper(p).part_position_m();
  const Eigen::Vector3d seat_part0 = seat_gripper(p).world_state().part_m;
  drive_with_deadman(p, true);
  ASSERT_TRUE(start_plate_move(p, {0.1e-3, -0.05e-3, 0, 0, 0, 1 * kSeatDeg}));
  settle_plate(p, 4.0);
  ASSERT_TRUE(p.positioner()->at_rest());
  const PlatformTransform T = p.simulation().positioner->true_pose();
  // In the seat's frame the part has not moved; in the world's it went where the plate went.
  EXPECT_LT((seat_gripper(p).world_state().part_m - seat_part0).norm(), 1e-12);
  EXPECT_LT((seat_gripper(p).part_position_m() - (T.R * seat_part0 + T.d)).norm(), 1e-9);
  std::printf("the part moved (%.3f, %.3f) um with the plate\n",
              1e6 * (seat_gripper(p).part_position_m() - part0).x(),
              1e6 * (seat_gripper(p).part_position_m() - part0).y());
  const Eigen::Vector3d turned = Eigen::AngleAxisd(1 * kSeatDeg, Eigen::Vector3d::UnitZ()) * part0;
  EXPECT_NEAR(seat_gripper(p).part_position_m().x(), turned.x() + 0.1e-3, 0.1e-6);
  EXPECT_NEAR(seat_gripper(p).part_position_m().y(), turned.y() - 0.05e-3, 0.1e-6);
  EXPECT_NEAR(seat_gripper(p).part_yaw_rad(), seat_gripper(p).world_state().part_yaw_rad + 1 * kSeatDeg,
              1e-6);
  // The camera draws the hole where the plate took it.
  PlatformConfig scene = c;
  scene.world = microworld::pin_in_hole_scene();
  CameraScenePose pose = initial_pose(scene);
  pose.seat_x_m = T.d.x(), pose.seat_y_m = T.d.y();
  pose.seat_yaw_rad = devices::CarriedSeat{T}.yaw_rad();
  imaging::SceneSnapshot snapshot;
  fill_camera_scene(scene, pose, snapshot);
  ASSERT_EQ(snapshot.holes.size(), 1u);
  const Eigen::Vector3d hole =
      T.R * Eigen::Vector3d(scene.world.target_m.x(), scene.world.target_m.y(), 0) + T.d;
  EXPECT_NEAR(snapshot.holes[0].x_m, hole.x(), 1e-9);
  EXPECT_NEAR(snapshot.holes[0].y_m, hole.y(), 1e-9);
  EXPECT_NEAR(snapshot.holes[0].angle_rad, 1 * kSeatDeg, 1e-6);
}

TEST(CarriedSeat, NeitherRobotBringsTheSeatAndTheTipsNearerThanTheirFloor) {
  PlatformConfig c;
  c.positioner = "parallel";
  c.stage.home_x_m = -1.5e-3;  // over the bare substrate, 60 um above it
  c.stage.home_z_m = 60e-6;
  Platform p{c};
  const double floor = c.world.min_tip_height_m;
  p.loop().run_for(2000);
  drive_with_deadman(p, true);
  const auto clearance = [&] { return seat_gripper(p).seat().to_seat(seat_gripper(p).tip_position_m()).z(); };
  // A move whose path would raise the seat within the floor is refused before anything moves.
  const PlatformTransform before = p.simulation().positioner->true_pose();
  EXPECT_FALSE(start_plate_move(p, {0, 0, 100e-6, 0, 0, 0}));
  p.loop().run_for(1000);
  EXPECT_LT((p.simulation().positioner->true_pose().d - before.d).norm(), 50e-9);
  // The plate rises 40 um while the console's joystick lowers the tips at 50 um/s: the gripper
  // stops at the floor over the rising seat, and the seat stops at the floor under the tips.
  ASSERT_TRUE(start_plate_move(p, {0, 0, 40e-6, 0, 0, 0}));
  teleop::ConsoleInput in = p.console_input();
  in.has_goal = false;
  in.velocity_m_s = {0, 0, -50e-6};
  p.set_console_input(in);
  double lowest = clearance();
  for (int i = 0; i < 20000; ++i) {
    p.loop().run_for(1);
    lowest = std::min(lowest, clearance());
  }
  std::printf(
      "plate up 40 um, tips down at 50 um/s: the tips' lowest over the seat %.3f um (floor %.0f um)\n",
      1e6 * lowest, 1e6 * floor);
  EXPECT_GT(lowest, floor - 0.2e-6);
  EXPECT_LT(clearance(), floor + 1e-6) << "they met at the floor";
  EXPECT_FALSE(seat_gripper(p).world_state().crashed);
  // Down again: a move away from the tips runs.
  in.velocity_m_s.setZero();
  p.set_console_input(in);
  ASSERT_TRUE(start_plate_move(p, {0, 0, 0, 0, 0, 0}));
  settle_plate(p, 4.0);
  EXPECT_LT(p.simulation().positioner->true_pose().d.norm(), 0.1e-6);
}

TEST(CarriedSeat, ASeatPressedIntoTheTipsStopsAtTheContactLimit) {
  PlatformConfig c;
  c.positioner = "parallel";
  c.stage.home_x_m = -1.5e-3;
  c.stage.home_z_m = 20e-6;
  c.world.min_tip_height_m = -50e-6;  // a floor below the substrate: only the contact limit acts
  Platform p{c};
  p.loop().run_for(2000);
  drive_with_deadman(p, true);
  ASSERT_TRUE(start_plate_move(p, {0, 0, 40e-6, 0, 0, 0}));  // 20 um into the tips
  double peak_N = 0.0;
  for (int i = 0; i < 40000 && !p.positioner()->at_rest(); ++i) {
    p.loop().run_for(1);
    peak_N = std::max(peak_N, p.gripper().contact_force_N().z);
  }
  ASSERT_TRUE(p.positioner()->at_rest());
  const double limit = c.world.contact_force_limit_N;
  EXPECT_GT(peak_N, limit) << "it went into the tips";
  // Stopped on the tick the press passed the limit: the legs end the stick-slip step under way (at
  // most ~0.1 um against the crash's 1e5 N/m, 10 mN), not the 20 um (2 N) the move asked for.
  EXPECT_LT(peak_N, 5 * limit);
  const double clearance = seat_gripper(p).seat().to_seat(seat_gripper(p).tip_position_m()).z();
  EXPECT_NEAR(clearance, 0.0, 0.1e-6) << "it holds at the touch";
  std::printf("peak contact %.3g mN, at rest %.2f nm from the tips\n", 1e3 * peak_N, 1e9 * clearance);
}

}  // namespace
}  // namespace mc::platform
