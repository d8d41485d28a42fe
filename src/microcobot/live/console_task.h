#pragma once
/// @file
/// The supervised task as the console server presents it (`serve --cell`, live_task.h): the
/// task_* actions checked against the task's state (a one-line answer for the ones that cannot
/// apply), the `task` member of `/platform/status`, and the events a recording keeps of it.
/// The server thread's and the status thread's; nothing here reaches the loop.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "microcobot/live/console_command.h"
#include "microcobot/live/live_task.h"

namespace mc::live {

/// The loop's control for a task_* console action.
TaskAction task_action(ConsoleAction a);
/// Its name on `/console/action` (task_start, ...).
std::string task_action_name(ConsoleAction a);

/// Why `a` cannot apply to the task in state `s` (empty: it may; the loop still ignores a
/// transition the task does not allow at that tick). `task` is nullopt without a task.
std::string task_action_refusal(ConsoleAction a, const std::optional<LiveTaskStatus>& task);

/// `null` without a task, else `{"steps": [{"name", "autonomy"}...], "started", "step",
/// "step_index", "status" (idle, running, paused, awaiting confirmation, operator, succeeded,
/// failed), "search_tries", "elapsed_s", "failure", "supervisor_lost", "heartbeat_gap", "inserted" (null,
/// true, false)}` (docs/console.md).
nlohmann::json task_status_json(const std::optional<LiveTaskStatus>& task);

/// What changed from `was` to `now`, as (event kind, message) pairs: the task started, its step,
/// its status, its end.
std::vector<std::pair<std::string, std::string>> task_changes(const std::optional<LiveTaskStatus>& was,
                                                              const std::optional<LiveTaskStatus>& now);

}  // namespace mc::live
