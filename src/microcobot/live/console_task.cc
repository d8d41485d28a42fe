#include "microcobot/live/console_task.h"

#include <fmt/format.h>

namespace mc::live {

using cell::AssemblyTask;
using Status = AssemblyTask::Status;

// The task's console actions are TaskAction's, in its order.
static_assert(static_cast<int>(ConsoleAction::kTaskSkip) - static_cast<int>(ConsoleAction::kTaskStart) ==
              static_cast<int>(TaskAction::kSkip));

TaskAction task_action(ConsoleAction a) {
  return static_cast<TaskAction>(static_cast<int>(a) - static_cast<int>(ConsoleAction::kTaskStart));
}

std::string task_action_name(ConsoleAction a) {
  static constexpr const char* kNames[] = {"task_start",     "task_pause",     "task_resume",
                                           "task_confirm",   "task_take_over", "task_hand_back",
                                           "task_step_done", "task_skip"};
  return kNames[static_cast<int>(task_action(a))];
}

std::string task_action_refusal(ConsoleAction a, const std::optional<LiveTaskStatus>& task) {
  if (!task) return "task: there is none (serve was started without --cell)";
  const LiveTaskStatus& s = *task;
  if (s.ended) return "task: it has ended (" + s.status_name() + "); Restart scene for another cycle";
  if (a == ConsoleAction::kTaskStart) return s.started ? "task: already started" : "";
  if (!s.started) return "task: not started; press Start";
  switch (a) {
    case ConsoleAction::kTaskPause:  // also while the platform holds it for a heartbeat gap: it stays paused
      return s.status == Status::kRunning || s.heartbeat_gap
                 ? ""
                 : "task: pause: it is not running (" + s.status_name() + ")";
    case ConsoleAction::kTaskResume:
      return s.status == Status::kPaused ? "" : "task: resume: it is not paused (" + s.status_name() + ")";
    case ConsoleAction::kTaskConfirm:
      return s.status == Status::kAwaitingConfirm ? "" : "task: confirm: no step awaits confirmation";
    case ConsoleAction::kTaskHandBack:
    case ConsoleAction::kTaskStepDone:
      return s.status == Status::kOperator || s.status == Status::kAssisted
                 ? ""
                 : "task: hand back: the operator does not drive it";
    default:
      return "";  // take over, skip: at any step
  }
}

nlohmann::json task_status_json(const std::optional<LiveTaskStatus>& task) {
  if (!task) return nullptr;
  const LiveTaskStatus& s = *task;
  nlohmann::json steps = nlohmann::json::array();
  for (int i = 0; i + 1 < AssemblyTask::kStepCount; ++i)
    steps.push_back({{"name", AssemblyTask::name(static_cast<AssemblyTask::Step>(i))},
                     {"autonomy", AssemblyTask::name(s.autonomy[static_cast<std::size_t>(i)])}});
  return {{"steps", steps},
          {"started", s.started},
          {"step", AssemblyTask::name(s.step)},
          {"step_index", static_cast<int>(s.step)},
          {"status", s.status_name()},
          {"search_tries", s.search_tries},
          {"elapsed_s", s.elapsed_s},
          {"failure", s.failure},
          {"supervisor_lost", s.supervisor_lost},
          {"heartbeat_gap", s.heartbeat_gap},
          {"looks", s.looks},
          {"looks_found", s.looks_found},
          {"look", s.look == AssemblyTask::Look::kNone ? nlohmann::json(nullptr)
                                                       : nlohmann::json(AssemblyTask::name(s.look))},
          {"part", s.part < 0 ? nlohmann::json(nullptr) : nlohmann::json(s.part)},
          {"parts", s.parts},
          {"inserted", s.inserted < 0 ? nlohmann::json(nullptr) : nlohmann::json(s.inserted == 1)}};
}

std::vector<std::pair<std::string, std::string>> task_changes(const std::optional<LiveTaskStatus>& was,
                                                              const std::optional<LiveTaskStatus>& now) {
  std::vector<std::pair<std::string, std::string>> out;
  if (!now) return out;
  const LiveTaskStatus& s = *now;
  const bool was_started = was && was->started;
  if (!s.started || (was_started && was->ended && s.ended)) return out;
  if (!was_started) out.emplace_back("task", "the task started");
  if (!was_started || was->step != s.step)
    out.emplace_back("task_step", std::string(AssemblyTask::name(s.step)));
  if (!was_started || was->status != s.status || was->supervisor_lost != s.supervisor_lost ||
      was->heartbeat_gap != s.heartbeat_gap) {
    std::string why;
    if (s.status == Status::kPaused && s.supervisor_lost)
      why = " (the console lost control or its heartbeat)";
    if (s.status == Status::kPaused && s.heartbeat_gap) why = " (a gap in the console's heartbeat)";
    out.emplace_back("task_status", s.status_name() + why);
  }
  if (s.ended && !(was && was->ended)) {
    std::string how = fmt::format("the task ended: {} in step {} after {:.1f} s", s.status_name(),
                                  AssemblyTask::name(s.step), s.elapsed_s);
    if (!s.failure.empty()) how += ": " + s.failure;
    if (s.inserted >= 0) how += s.inserted ? "; the pin is in its bore" : "; the pin is not in its bore";
    out.emplace_back("task_end", how);
  }
  return out;
}

}  // namespace mc::live
