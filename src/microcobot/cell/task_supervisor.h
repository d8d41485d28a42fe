#pragma once
/// @file
/// Who drives an assembly task and whether it runs: the operator's side of the task
/// (assembly_task.h, "Status"). Each step begins at the level of autonomy the operator set for it
/// (robot, robot after a confirmation, operator, operator under shared control); the operator
/// pauses, resumes, confirms and takes over; a failure or the last step ends it. The supervisor
/// holds no motion: the task's steps move, the supervisor says whether they may. Never allocates;
/// noexcept.

#include <array>
#include <string_view>

#include "microcobot/cell/task_steps.h"

namespace mc::cell {

class TaskSupervisor {
 public:
  TaskSupervisor() noexcept { autonomy_.fill(StepAutonomy::kAuto); }

  /// A step begins at its level: running, awaiting confirmation, the operator's or assisted
  /// (kDone: succeeded).
  void begin(TaskStep step) noexcept;
  /// Back to the step after a look: assisted where its level says so, running otherwise.
  void after_look(TaskStep step) noexcept;
  /// The robot drives the step again (the operator handed it back).
  void run() noexcept { status_ = TaskStatus::kRunning; }
  /// The task holds while the camera looks.
  void await_look() noexcept { status_ = TaskStatus::kAwaitingLook; }
  /// The task ends failed; `why` a static string.
  void fail(const char* why) noexcept;

  void pause() noexcept;
  void resume() noexcept;
  void confirm() noexcept;
  void take_over() noexcept;

  void set_autonomy(TaskStep step, StepAutonomy a) noexcept { autonomy_[step_index(step)] = a; }
  StepAutonomy autonomy(TaskStep step) const noexcept { return autonomy_[step_index(step)]; }

  TaskStatus status() const noexcept { return status_; }
  /// The operator's master drives the stage (taken over, a manual or an assisted step).
  bool operator_drives() const noexcept {
    return status_ == TaskStatus::kOperator || status_ == TaskStatus::kAssisted;
  }
  bool finished() const noexcept {
    return status_ == TaskStatus::kSucceeded || status_ == TaskStatus::kFailed;
  }
  /// Why the task failed ("" otherwise); a static string.
  std::string_view failure() const noexcept { return failure_; }

 private:
  std::array<StepAutonomy, kTaskStepCount> autonomy_{};
  TaskStatus status_ = TaskStatus::kRunning;
  const char* failure_ = "";
};

}  // namespace mc::cell
