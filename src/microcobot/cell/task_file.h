#pragma once
/// @file
/// A task in YAML: the automatic insertion's autonomy per
/// step (FlexBE-like levels: `auto` runs it, `confirm` waits for the operator's go before it
/// starts, `manual` hands it to the operator, `assisted` hands it to the operator under the
/// platform's guidance (AssemblyTask::assistable()) and goes on once its goal is reached) and overrides of
/// its parameters (AssemblyTaskParams), e.g.
///
///     steps: {insert: confirm, release: confirm}
///     params: {insert_speed_m_s: 1e-5}
///
/// Read by `microcobot cell run --task FILE` and `microcobot serve --cell --task FILE`. Unknown
/// keys (a misspelt step or parameter) and levels other than the four are refused with one line
/// naming them (mc::InvalidInput "file:line: unknown key 'steps.inserting' (known: ...)",
/// mc::InvalidParams "steps.insert: must be auto, confirm, manual or assisted"; "steps.grasp:
/// assisted is for approach, ...").

#include <array>
#include <filesystem>
#include <string>

#include "microcobot/cell/assembly_task.h"

namespace mc::cell {

/// The autonomy of each step of AssemblyTask, by the step's name.
struct TaskStepsParams {
  std::string approach = "auto";
  std::string align = "auto";
  std::string descend = "auto";
  std::string grasp = "auto";
  std::string lift = "auto";
  std::string transport = "auto";
  std::string rotate = "auto";
  std::string insert = "auto";
  std::string release = "auto";
  std::string retract = "auto";
  std::string verify = "auto";

  template <class V>
  void visit(V& v) {
    v("approach", approach);
    v("align", align);
    v("descend", descend);
    v("grasp", grasp);
    v("lift", lift);
    v("transport", transport);
    v("rotate", rotate);
    v("insert", insert);
    v("release", release);
    v("retract", retract);
    v("verify", verify);
  }
  void validate() const;
  /// Indexed by AssemblyTask::Step (kDone: auto). Throws like validate().
  std::array<AssemblyTask::Autonomy, AssemblyTask::kStepCount> autonomy() const;
};

/// A task file: the steps' autonomy and the task's parameters.
struct AssemblyTaskFile {
  TaskStepsParams steps;
  AssemblyTaskParams params;

  template <class V>
  void visit(V& v) {
    v("steps", steps);
    v("params", params);
  }
  void validate() const;
  /// Sets every step's autonomy on `task`.
  void apply(AssemblyTask& task) const;
};

/// Reads a task file over `params` (e.g. the run's `task` keys): the file's `params` override
/// them. Throws mc::InvalidInput / mc::InvalidParams naming the file and the key.
AssemblyTaskFile load_task_file(const std::filesystem::path& file, const AssemblyTaskParams& params = {});

/// The same from YAML text (tests); `source` names it in errors.
AssemblyTaskFile task_file_from_yaml(const std::string& text, const AssemblyTaskParams& params = {});

}  // namespace mc::cell
