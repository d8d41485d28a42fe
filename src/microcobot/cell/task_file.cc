#include "microcobot/cell/task_file.h"

#include <string_view>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "microcobot/core/params.h"

namespace mc::cell {
namespace {

using Autonomy = AssemblyTask::Autonomy;

Autonomy autonomy_of(const std::string& level, const char* step, AssemblyTask::Step s) {
  for (Autonomy a : {Autonomy::kAuto, Autonomy::kConfirm, Autonomy::kManual, Autonomy::kAssisted})
    if (AssemblyTask::name(a) == level) {
      if (a == Autonomy::kAssisted && !AssemblyTask::assistable(s))
        throw InvalidParams(
            std::string("steps.") + step,
            "assisted is for approach, align, descend, grasp, lift, transport, rotate, insert, release and "
            "retract");
      return a;
    }
  throw InvalidParams(std::string("steps.") + step,
                      "must be auto, confirm, manual or assisted, not '" + excerpt(level) + "'");
}

// Each step's level, at its index in AssemblyTask::Step (found by its name).
struct StepIndexer {
  std::array<Autonomy, AssemblyTask::kStepCount>* out;
  void operator()(const char* key, const std::string& level) {
    for (int i = 0; i < AssemblyTask::kStepCount; ++i)
      if (AssemblyTask::name(static_cast<AssemblyTask::Step>(i)) == key)
        (*out)[static_cast<std::size_t>(i)] = autonomy_of(level, key, static_cast<AssemblyTask::Step>(i));
  }
};

AssemblyTaskFile read(const YAML::Node& node, const std::string& source, const AssemblyTaskParams& params) {
  AssemblyTaskFile f;
  f.params = params;
  if (!node.IsNull()) {
    detail::YamlReader reader(node, source, "");
    f.visit(reader);
    reader.reject_unknown_keys();
  }
  try {
    f.validate();
  } catch (const InvalidParams& e) {
    throw InvalidInput(source, 0, e.what());  // the file named with the key
  }
  return f;
}

}  // namespace

std::array<Autonomy, AssemblyTask::kStepCount> TaskStepsParams::autonomy() const {
  std::array<Autonomy, AssemblyTask::kStepCount> out{};
  out.fill(Autonomy::kAuto);
  StepIndexer v{&out};
  TaskStepsParams copy = *this;  // visit() is not const
  copy.visit(v);
  return out;
}

void TaskStepsParams::validate() const { (void)autonomy(); }

void AssemblyTaskFile::validate() const {
  steps.validate();
  try {
    params.validate();
  } catch (const InvalidParams& e) {
    // Named as the file spells it (params.insert_speed_m_s).
    const std::string what = e.what(), head = "invalid parameter " + e.field() + ": ";
    throw InvalidParams("params." + e.field(), what.rfind(head, 0) == 0 ? what.substr(head.size()) : what);
  }
}

void AssemblyTaskFile::apply(AssemblyTask& task) const {
  const auto levels = steps.autonomy();
  for (int i = 0; i < AssemblyTask::kStepCount - 1; ++i)
    task.set_autonomy(static_cast<AssemblyTask::Step>(i), levels[static_cast<std::size_t>(i)]);
}

AssemblyTaskFile load_task_file(const std::filesystem::path& file, const AssemblyTaskParams& params) {
  return read(detail::parse_yaml_file(file), file.string(), params);
}

AssemblyTaskFile task_file_from_yaml(const std::string& text, const AssemblyTaskParams& params) {
  return read(detail::parse_yaml_text(text, "<yaml>"), "<yaml>", params);
}

}  // namespace mc::cell
