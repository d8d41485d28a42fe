#include "microcobot/live/console_pose_goal.h"

#include <cmath>

#include <Eigen/Geometry>

#include <fmt/format.h>

#include "microcobot/devices/carried_seat.h"
#include "microcobot/motion/parallel_workspace.h"
#include "microcobot/motion/pose.h"

namespace mc::live {
namespace {

// A goal is reached (or the same goal) within a nanometre and a nanoradian: the move's last
// reference is its goal, so the loop's own rounding is all that may differ.
constexpr double kSame_m = 1e-9, kSame_rad = 1e-9;

bool same_pose(const motion::PlatformTransform& a, const motion::PlatformTransform& b) {
  const Eigen::AngleAxisd turn(a.R.transpose() * b.R);
  return (a.d - b.d).norm() <= kSame_m && std::abs(turn.angle()) <= kSame_rad;
}

}  // namespace

motion::PlatformTransform pose_goal_transform(const ConsoleCommand& c) {
  const auto& g = c.pose_goal;
  motion::PlatformTransform T;
  T.R = motion::smarpod_rotation(g[3], g[4], g[5]);
  T.d = Eigen::Vector3d(g[0], g[1], g[2]);
  return T;
}

ConsolePoseGoal::ConsolePoseGoal(const motion::ParallelGeometryParams& geometry,
                                 const motion::PoseMoveLimits& limits)
    : kinematics_(geometry), limits_(limits) {
  limits_.validate();
}

ConsolePoseGoal::Step ConsolePoseGoal::on_command(const ConsoleCommand& c, const ConsolePoseView& v) {
  Step step;
  if (seq_ > v.handled_seq) return step;  // the loop has not taken the last one yet
  if (!c.has_pose_goal) {
    // The operator stopped asking: a move of the console's ends where it is.
    if (v.moving && goal_) {
      goal_.reset();
      step.push = ConsolePoseMove{++seq_, std::nullopt};
    }
    return step;
  }
  if (!c.deadman) return step;  // the platform holds without it; the goal waits for it
  const motion::PlatformTransform goal = pose_goal_transform(c);
  if (v.moving) {
    // Towards this goal already; another goal stops it first (the next command plans from there).
    if (!(goal_ && same_pose(*goal_, goal))) {
      goal_.reset();
      step.push = ConsolePoseMove{++seq_, std::nullopt};
    }
    return step;
  }
  if (same_pose(v.reference, goal)) return step;            // arrived
  if (refused_ && same_pose(*refused_, goal)) return step;  // told already
  // The goal's own check first: it bounds the path's length, and so the samples check_move() takes
  // along it (a goal a light-year away is refused here, not sampled).
  const motion::ReachCheck reach = motion::check_pose(kinematics_, goal);
  if (!reach.ok()) {
    refused_ = goal;
    step.refusal = "the goal is unreachable: " + motion::to_string(reach.reach) +
                   (reach.detail.empty() ? "" : ": " + reach.detail);
    return step;
  }
  motion::PoseTrajectory trajectory(v.reference, goal, limits_);
  const motion::MoveCheck check = motion::check_move(kinematics_, trajectory);
  if (!check.ok) {
    refused_ = goal;
    step.refusal = check.reason;
    return step;
  }
  // The seat on the plate must keep clear of the finger tips over it (Platform::start_pose_move
  // refuses such a move as well; here it is said why).
  const double lowest = devices::lowest_tip_height_m(trajectory, v.tips_m, v.seat_on_plate);
  if (lowest < v.tip_floor_m) {
    refused_ = goal;
    step.refusal =
        fmt::format("the seat would come within {:.1f} um of the finger tips (their floor: {:.0f} um)",
                    1e6 * std::max(lowest, 0.0), 1e6 * v.tip_floor_m);
    return step;
  }
  refused_.reset();
  goal_ = goal;
  step.push = ConsolePoseMove{++seq_, std::move(trajectory)};
  return step;
}

}  // namespace mc::live
