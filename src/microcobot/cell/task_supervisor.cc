#include "microcobot/cell/task_supervisor.h"

namespace mc::cell {

void TaskSupervisor::begin(TaskStep step) noexcept {
  if (step == TaskStep::kDone) {
    status_ = TaskStatus::kSucceeded;
    return;
  }
  switch (autonomy(step)) {
    case StepAutonomy::kAuto:
      status_ = TaskStatus::kRunning;
      break;
    case StepAutonomy::kConfirm:
      status_ = TaskStatus::kAwaitingConfirm;
      break;
    case StepAutonomy::kManual:
      status_ = TaskStatus::kOperator;
      break;
    case StepAutonomy::kAssisted:
      status_ = step_assistable(step) ? TaskStatus::kAssisted : TaskStatus::kOperator;
      break;
  }
}

void TaskSupervisor::after_look(TaskStep step) noexcept {
  status_ = autonomy(step) == StepAutonomy::kAssisted && step_assistable(step) ? TaskStatus::kAssisted
                                                                               : TaskStatus::kRunning;
}

void TaskSupervisor::fail(const char* why) noexcept {
  failure_ = why;
  status_ = TaskStatus::kFailed;
}

void TaskSupervisor::pause() noexcept {
  if (status_ == TaskStatus::kRunning) status_ = TaskStatus::kPaused;
}

void TaskSupervisor::resume() noexcept {
  if (status_ == TaskStatus::kPaused) status_ = TaskStatus::kRunning;
}

void TaskSupervisor::confirm() noexcept {
  if (status_ == TaskStatus::kAwaitingConfirm) status_ = TaskStatus::kRunning;
}

void TaskSupervisor::take_over() noexcept {
  if (!finished()) status_ = TaskStatus::kOperator;
}

}  // namespace mc::cell
