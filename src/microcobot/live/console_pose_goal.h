#pragma once
/// @file
/// The console's go-to pose for the parallel positioner (`/console/command` "pose_goal",
/// docs/console.md): the controlling client sends its goal with every command while the operator
/// holds the deadman; the server plans and checks each move here, off the loop, and the loop
/// starts it (ConsoleSource) only while the deadman is held. A goal that cannot be reached is
/// refused with its reason before anything moves (motion::check_move), once per goal. Releasing
/// the deadman holds the platform where it is (Platform::devices_task); holding it again plans
/// the rest of the way from there. A new goal while a move runs stops it first, then plans from
/// where the legs hold.
///
/// Server thread only (one instance per console server).

#include <cstdint>
#include <limits>
#include <optional>
#include <string>

#include "microcobot/live/console_command.h"
#include "microcobot/motion/parallel_kinematics.h"
#include "microcobot/motion/pose_trajectory.h"

namespace mc::live {

/// A move for the loop, or a stop (no trajectory): the console's pose ring's element.
struct ConsolePoseMove {
  std::uint64_t seq = 0;
  std::optional<motion::PoseTrajectory> trajectory;  ///< checked; none: stop the move under way
};

/// What the loop last published of the positioner for the console (ConsoleSource).
struct ConsolePoseView {
  motion::PlatformTransform reference;  ///< the pose the legs are told to be at
  bool moving = false;                  ///< a pose move runs, or a jog moves it
  bool jogging = false;                 ///< a jog drives it (it follows the jog's target)
  bool at_edge = false;                 ///< the jog stopped at the workspace's edge
  std::uint64_t handled_seq = 0;        ///< the last ConsolePoseMove the loop took (started, or dropped)
  /// Where the finger tips stand (world frame), and how near the seat may come to them (the
  /// platform's world.min_tip_height_m): a goal whose path brings it nearer is refused.
  Eigen::Vector3d tips_m = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  double tip_floor_m = 0.0;
  motion::PlatformTransform seat_on_plate;  ///< the seat's pose on the plate as measured
};

/// The goal of a command as the transform of {P} in {H} (R = Rz(rz) Ry(ry) Rx(rx)).
motion::PlatformTransform pose_goal_transform(const ConsoleCommand& c);

class ConsolePoseGoal {
 public:
  /// `limits`: the moves' speed and acceleration limits (motion::PoseMoveLimits' defaults: the
  /// SmarPod class's scanning speeds, docs/parameters.md).
  explicit ConsolePoseGoal(const motion::ParallelGeometryParams& geometry,
                           const motion::PoseMoveLimits& limits = {});

  /// What one command of the controlling client asks of the loop, given what the loop last
  /// published: a move or a stop to push, a refusal (one line, the goal's first command only),
  /// or nothing (no goal, no deadman, a move pending or running towards this goal, or arrived).
  struct Step {
    std::optional<ConsolePoseMove> push;
    std::string refusal;
  };
  Step on_command(const ConsoleCommand& c, const ConsolePoseView& v);
  /// The last step's move could not be pushed (the ring was full): the next command plans again.
  void not_sent() noexcept {
    --seq_;
    goal_.reset();
  }

 private:
  motion::ParallelKinematics kinematics_;
  motion::PoseMoveLimits limits_;
  std::uint64_t seq_ = 0;
  std::optional<motion::PlatformTransform> goal_;     // the goal of the last move pushed
  std::optional<motion::PlatformTransform> refused_;  // the last goal refused (told once)
};

}  // namespace mc::live
