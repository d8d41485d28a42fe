// The task's supervisor: each step begins at the operator's level for it, the operator's requests
// act only from the statuses they are meant for, and a finished task stays finished.
#include "microcobot/cell/task_supervisor.h"

#include <gtest/gtest.h>

namespace mc::cell {
namespace {

TEST(TaskSupervisor, EachStepBeginsAtItsLevel) {
  TaskSupervisor s;
  s.begin(TaskStep::kApproach);
  EXPECT_EQ(s.status(), TaskStatus::kRunning);
  s.set_autonomy(TaskStep::kGrasp, StepAutonomy::kConfirm);
  s.begin(TaskStep::kGrasp);
  EXPECT_EQ(s.status(), TaskStatus::kAwaitingConfirm);
  s.set_autonomy(TaskStep::kInsert, StepAutonomy::kManual);
  s.begin(TaskStep::kInsert);
  EXPECT_EQ(s.status(), TaskStatus::kOperator);
  EXPECT_TRUE(s.operator_drives());
  s.set_autonomy(TaskStep::kTransport, StepAutonomy::kAssisted);
  s.begin(TaskStep::kTransport);
  EXPECT_EQ(s.status(), TaskStatus::kAssisted);
  // Verify cannot be assisted: given that level, it is the operator's.
  s.set_autonomy(TaskStep::kVerify, StepAutonomy::kAssisted);
  s.begin(TaskStep::kVerify);
  EXPECT_EQ(s.status(), TaskStatus::kOperator);
  s.begin(TaskStep::kDone);
  EXPECT_EQ(s.status(), TaskStatus::kSucceeded);
  EXPECT_TRUE(s.finished());
}

TEST(TaskSupervisor, RequestsActOnlyFromTheirStatus) {
  TaskSupervisor s;
  s.set_autonomy(TaskStep::kLift, StepAutonomy::kConfirm);
  s.begin(TaskStep::kLift);
  s.pause();  // awaiting a confirmation is not running: nothing to pause
  EXPECT_EQ(s.status(), TaskStatus::kAwaitingConfirm);
  s.resume();
  EXPECT_EQ(s.status(), TaskStatus::kAwaitingConfirm);
  s.confirm();
  EXPECT_EQ(s.status(), TaskStatus::kRunning);
  s.confirm();
  EXPECT_EQ(s.status(), TaskStatus::kRunning);
  s.pause();
  EXPECT_EQ(s.status(), TaskStatus::kPaused);
  s.resume();
  EXPECT_EQ(s.status(), TaskStatus::kRunning);
  s.await_look();
  s.after_look(TaskStep::kLift);
  EXPECT_EQ(s.status(), TaskStatus::kRunning);
  s.set_autonomy(TaskStep::kLift, StepAutonomy::kAssisted);
  s.await_look();
  s.after_look(TaskStep::kLift);
  EXPECT_EQ(s.status(), TaskStatus::kAssisted);
  s.take_over();
  EXPECT_EQ(s.status(), TaskStatus::kOperator);
  s.run();
  EXPECT_EQ(s.status(), TaskStatus::kRunning);
}

TEST(TaskSupervisor, AFailureEndsTheTaskAndTheOperatorCannotTakeOverAFinishedOne) {
  TaskSupervisor s;
  s.begin(TaskStep::kApproach);
  EXPECT_EQ(s.failure(), "");
  s.fail("a step took longer than step_timeout_s");
  EXPECT_TRUE(s.finished());
  EXPECT_EQ(s.failure(), "a step took longer than step_timeout_s");
  s.take_over();
  s.resume();
  s.confirm();
  EXPECT_EQ(s.status(), TaskStatus::kFailed);
}

}  // namespace
}  // namespace mc::cell
