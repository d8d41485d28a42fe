#pragma once
/// @file
/// The vocabulary of the assembly task (assembly_task.h): its steps in order, the statuses a
/// supervisor gives it, the levels of autonomy an operator sets per step, and the camera's looks
/// with what one saw. Shared by the task, its supervisor (task_supervisor.h), its looks
/// (task_looks.h) and its insertion (insertion_search.h).

#include <cstddef>

#include <Eigen/Dense>

namespace mc::cell {

/// The steps of one pick-and-insert, in the order they run (assembly_task.h describes each).
enum class TaskStep {
  kApproach,
  kAlign,
  kDescend,
  kGrasp,
  kLift,
  kTransport,
  kRotate,
  kInsert,
  kRelease,
  kRetract,
  kVerify,
  kDone
};
inline constexpr int kTaskStepCount = 12;
inline constexpr std::size_t step_index(TaskStep s) noexcept { return static_cast<std::size_t>(s); }
/// The step after `s` (kDone stays kDone).
inline constexpr TaskStep next_step(TaskStep s) noexcept {
  return s == TaskStep::kDone ? s : static_cast<TaskStep>(step_index(s) + 1);
}

/// Who drives and whether the task runs (task_supervisor.h).
enum class TaskStatus {
  kRunning,
  kPaused,
  kAwaitingConfirm,
  kAwaitingLook,
  kOperator,
  kSucceeded,
  kFailed,
  kAssisted
};

/// A step's level: the robot's, the robot's after the operator confirms, the operator's, or the
/// operator's under the task's shared control (the moves only: step_assistable(); another step
/// given it is the operator's).
enum class StepAutonomy { kAuto, kConfirm, kManual, kAssisted };

/// The steps that may be assisted (assembly_task.h, AssemblyTask::assistable, says how each is).
inline constexpr bool step_assistable(TaskStep s) noexcept {
  return s != TaskStep::kVerify && s != TaskStep::kDone;
}

/// The camera's looks (assembly_task.h, "Looks").
enum class TaskLook { kNone, kSlot, kBore, kHeld, kPlaced, kAlign };

/// What a look saw (world frame): the pin's centre and yaw, or nothing; an align look also the
/// servo's error (the pin's centre minus the bore's) and whether it converged.
struct TaskSighting {
  bool found = false;
  Eigen::Vector3d part_m = Eigen::Vector3d::Zero();
  double yaw_rad = 0.0;
  Eigen::Vector2d error_m = Eigen::Vector2d::Zero();
  bool converged = false;
};

}  // namespace mc::cell
