// Tasks in YAML: each step's autonomy and the task's parameters read from a
// file; misspelt steps and keys, unknown levels and bad values refused with one line naming them.
#include "microcobot/cell/task_file.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "microcobot/core/error.h"
#include "support/test_support.h"

namespace mc::cell {
namespace {

using Step = AssemblyTask::Step;
using Autonomy = AssemblyTask::Autonomy;

// The message of what `f` throws (empty when it throws nothing).
template <class F>
std::string task_file_error(F f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(TaskFile, ReadsEachStepsAutonomyAndOverridesTheParameters) {
  AssemblyTaskParams base;
  base.travel_speed_m_s = 300e-6;  // e.g. from the run's --params: kept unless the file says
  const AssemblyTaskFile f = task_file_from_yaml(
      "steps: {insert: confirm, release: manual}\n"
      "params:\n  insert_speed_m_s: 1e-5\n  search_range_m: 30e-6\n",
      base);
  const auto a = f.steps.autonomy();
  EXPECT_EQ(a[static_cast<std::size_t>(Step::kInsert)], Autonomy::kConfirm);
  EXPECT_EQ(a[static_cast<std::size_t>(Step::kRelease)], Autonomy::kManual);
  EXPECT_EQ(a[static_cast<std::size_t>(Step::kApproach)], Autonomy::kAuto);
  EXPECT_EQ(a[static_cast<std::size_t>(Step::kRetract)], Autonomy::kAuto);
  EXPECT_DOUBLE_EQ(f.params.insert_speed_m_s, 1e-5);
  EXPECT_DOUBLE_EQ(f.params.search_range_m, 30e-6);
  EXPECT_DOUBLE_EQ(f.params.travel_speed_m_s, 300e-6);

  // Applied to a task: its steps' levels.
  AssemblyTask task(f.params, AssemblyGoal{});
  f.apply(task);
  EXPECT_EQ(task.autonomy(Step::kInsert), Autonomy::kConfirm);
  EXPECT_EQ(task.autonomy(Step::kRelease), Autonomy::kManual);
  EXPECT_EQ(task.autonomy(Step::kGrasp), Autonomy::kAuto);
}

TEST(TaskFile, AnEmptyFileIsTheAutomaticTaskWithTheGivenParameters) {
  const AssemblyTaskFile f = task_file_from_yaml("");
  for (Autonomy a : f.steps.autonomy()) EXPECT_EQ(a, Autonomy::kAuto);
  EXPECT_DOUBLE_EQ(f.params.insert_speed_m_s, AssemblyTaskParams{}.insert_speed_m_s);
}

TEST(TaskFile, RefusesUnknownStepsKeysAndLevelsWithOneLineNamingThem) {
  const auto one_line = [](const std::string& m) { return !m.empty() && m.find('\n') == std::string::npos; };
  std::string m = task_file_error([] { task_file_from_yaml("steps: {inserting: confirm}\n"); });
  EXPECT_TRUE(one_line(m)) << m;
  EXPECT_NE(m.find("steps.inserting"), std::string::npos) << m;
  EXPECT_NE(m.find("insert"), std::string::npos) << "lists the known steps: " << m;

  m = task_file_error([] { task_file_from_yaml("params: {insert_speed: 1e-5}\n"); });
  EXPECT_TRUE(one_line(m)) << m;
  EXPECT_NE(m.find("params.insert_speed"), std::string::npos) << m;

  m = task_file_error([] { task_file_from_yaml("step: {insert: confirm}\n"); });
  EXPECT_NE(m.find("'step'"), std::string::npos) << m;

  m = task_file_error([] { task_file_from_yaml("steps: {insert: sometimes}\n"); });
  EXPECT_TRUE(one_line(m)) << m;
  EXPECT_NE(m.find("steps.insert"), std::string::npos) << m;
  EXPECT_NE(m.find("sometimes"), std::string::npos) << m;

  m = task_file_error([] { task_file_from_yaml("steps: {verify: assisted}\n"); });
  EXPECT_TRUE(one_line(m)) << m;
  EXPECT_NE(m.find("steps.verify"), std::string::npos) << m;
  EXPECT_NE(m.find("assisted is for approach"), std::string::npos) << m;
  EXPECT_EQ(task_file_from_yaml("steps: {transport: assisted}\n")
                .steps.autonomy()[static_cast<std::size_t>(Step::kTransport)],
            Autonomy::kAssisted);
  EXPECT_EQ(task_file_from_yaml("steps: {rotate: assisted}\n")
                .steps.autonomy()[static_cast<std::size_t>(Step::kRotate)],
            Autonomy::kAssisted);

  m = task_file_error([] { task_file_from_yaml("params: {insert_speed_m_s: -1}\n"); });
  EXPECT_TRUE(one_line(m)) << m;
  EXPECT_NE(m.find("params.insert_speed_m_s"), std::string::npos) << m;

  m = task_file_error([] { task_file_from_yaml("steps: [insert]\n"); });
  EXPECT_TRUE(one_line(m)) << m;
  EXPECT_NE(m.find("steps"), std::string::npos) << m;
}

TEST(TaskFile, AFileIsNamedInItsErrorsWithTheLine) {
  mc::test::TempDir dir;
  const auto file = dir.path() / "task.yaml";
  std::ofstream(file) << "steps:\n  insert: confirm\n  grab: auto\n";
  const std::string m = task_file_error([&] { load_task_file(file); });
  EXPECT_NE(m.find("task.yaml:3"), std::string::npos) << m;
  EXPECT_NE(m.find("steps.grab"), std::string::npos) << m;
  std::ofstream(file) << "steps: {insert: confirm}\n";
  EXPECT_EQ(load_task_file(file).steps.insert, "confirm");
}

}  // namespace
}  // namespace mc::cell
