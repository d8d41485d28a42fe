// The names of the assembly task's steps, statuses, looks and autonomy levels (assembly_task.h), as
// the console, the task files and the results spell them.
#include <array>

#include "microcobot/cell/assembly_task.h"

namespace mc::cell {

std::string_view AssemblyTask::name(Step s) noexcept {
  static constexpr std::array<std::string_view, kStepCount> names = {
      "approach", "align",  "descend", "grasp",   "lift",   "transport",
      "rotate",   "insert", "release", "retract", "verify", "done"};
  return names[step_index(s)];
}

std::string_view AssemblyTask::name(Status s) noexcept {
  switch (s) {
    case Status::kRunning:
      return "running";
    case Status::kPaused:
      return "paused";
    case Status::kAwaitingConfirm:
      return "awaiting confirmation";
    case Status::kAwaitingLook:
      return "awaiting look";
    case Status::kOperator:
      return "operator";
    case Status::kSucceeded:
      return "succeeded";
    case Status::kFailed:
      return "failed";
    case Status::kAssisted:
      return "assisted";
  }
  return "?";
}

std::string_view AssemblyTask::name(Look l) noexcept {
  switch (l) {
    case Look::kNone:
      return "none";
    case Look::kSlot:
      return "slot";
    case Look::kBore:
      return "bore";
    case Look::kHeld:
      return "held";
    case Look::kAlign:
      return "align";
    case Look::kPlaced:
      return "placed";
  }
  return "?";
}

std::string_view AssemblyTask::name(Autonomy a) noexcept {
  switch (a) {
    case Autonomy::kAuto:
      return "auto";
    case Autonomy::kConfirm:
      return "confirm";
    case Autonomy::kManual:
      return "manual";
    case Autonomy::kAssisted:
      return "assisted";
  }
  return "?";
}

}  // namespace mc::cell
