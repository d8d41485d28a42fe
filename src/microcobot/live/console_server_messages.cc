// The console server's side of the clients' messages: the controlling client's commands (and
// the go-to pose planned from them), the actions, control and its hand-over, and the one-line
// status that answers each refusal (docs/console.md, "Client channels").
#include <chrono>
#include <string>

#include "microcobot/core/error.h"
#include "microcobot/live/console_server.h"
#include "microcobot/live/console_task.h"

namespace mc::live {

using server::StatusLevel;

void ConsoleServer::tell(server::ClientId client, StatusLevel level, const std::string& message,
                         std::string_view kind, std::string_view id) {
  if (client == 0)
    server_.broadcast_status(level, message, id);
  else
    server_.send_status(client, level, message, id);
  note(static_cast<EventLevel>(static_cast<int>(level)), kind, message, client);  // the same scale
}

void ConsoleServer::on_message(const server::ClientMessage& m) {
  const server::ClientId controller = controller_.load();
  if (recording_ && (m.topic == "/console/command" || m.topic == "/console/action")) {
    recording_->received(m.topic == "/console/command" ? RecordedTopic::kCommand : RecordedTopic::kAction,
                         m.client, live_.status().t_s, m.payload);
  }
  try {
    if (m.topic == "/console/command") {
      ConsoleCommand c = parse_console_command(m.payload, live_.limits());
      c.received_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                          std::chrono::steady_clock::now().time_since_epoch())
                          .count();
      if (m.client != controller) {
        tell(m.client, StatusLevel::kWarning, "control: take control first; command ignored", "refused",
             "control");
        return;
      }
      if (!live_.push_command(c)) {
        tell(m.client, StatusLevel::kWarning, "/console/command: the loop is busy; command dropped",
             "refused", "/console/command");
        return;
      }
      if (pose_goal_) {
        const ConsolePoseGoal::Step step = pose_goal_->on_command(c, live_.console_pose_view());
        if (!step.refusal.empty())
          tell(m.client, StatusLevel::kError, "/console/command: pose_goal: " + step.refusal, "refused",
               "/console/command");
        else if (step.push && !live_.push_console_pose_move(*step.push))
          pose_goal_->not_sent();  // planned again with the next command
      }
      return;
    }
    if (m.topic != "/console/action") {
      tell(m.client, StatusLevel::kError,
           "unknown topic '" + std::string(m.topic.substr(0, 80)) +
               "': the console publishes /console/command and /console/action",
           "refused", "unknown-topic");
      return;
    }
    const ActionRequest request = parse_action_request(m.payload);
    const ConsoleAction a = request.action;
    switch (a) {
      case ConsoleAction::kEstop:  // anyone may stop the platform
        live_.estop();
        tell(0, StatusLevel::kWarning, "e-stop pressed: every device in its safe state", "estop");
        return;
      case ConsoleAction::kTakeControl: {
        const server::ClientId previous = controller_.exchange(m.client);
        if (previous != 0 && previous != m.client)
          tell(previous, StatusLevel::kInfo, "control: taken by another client", "control_lost", "control");
        live_.push_command(ConsoleCommand{});  // the new controller starts from rest
        live_.set_console_in_control(true);
        tell(m.client, StatusLevel::kInfo, "control: granted", "take_control", "control");
        return;
      }
      case ConsoleAction::kReleaseControl:
        if (m.client == controller) on_disconnect(m.client);
        tell(m.client, StatusLevel::kInfo, "control: released", "release_control", "control");
        return;
      case ConsoleAction::kRecordStart: {
        const std::string name = start_recording(request.video);
        server_.broadcast_status(StatusLevel::kInfo, "recording to " + name);
        return;
      }
      case ConsoleAction::kRecordStop:
        note(EventLevel::kInfo, "record_stop", "recording stopped by a client", m.client);
        stop_recording();
        server_.broadcast_status(StatusLevel::kInfo, "recording stopped");
        return;
      case ConsoleAction::kVisionTare:
        if (m.client != controller) {
          tell(m.client, StatusLevel::kWarning, "control: take control first; action ignored", "refused",
               "control");
        } else if (!live_.request_vision_tare()) {
          tell(m.client, StatusLevel::kWarning,
               "vision_tare: no force by vision here (vision_force.enabled, a camera)", "refused",
               "vision_tare");
        } else {
          note(EventLevel::kInfo, "vision_tare", "force by vision tared at the next frame", m.client);
        }
        return;
      case ConsoleAction::kLevelTips:
        if (m.client != controller) {
          tell(m.client, StatusLevel::kWarning, "control: take control first; action ignored", "refused",
               "control");
        } else if (!live_.request_tip_levelling()) {
          tell(m.client, StatusLevel::kWarning, "level_tips: the gripper has no align drives", "refused",
               "level_tips");
        } else {
          note(EventLevel::kInfo, "level_tips", "tip levelling requested: it runs while the deadman is held",
               m.client);
        }
        return;
      case ConsoleAction::kReset:
      case ConsoleAction::kDemo:
      case ConsoleAction::kRestart:
      case ConsoleAction::kNextPart:
        if (m.client != controller) {
          tell(m.client, StatusLevel::kWarning, "control: take control first; action ignored", "refused",
               "control");
          return;
        }
        note(EventLevel::kInfo,
             a == ConsoleAction::kReset      ? "reset"
             : a == ConsoleAction::kDemo     ? "demo_requested"
             : a == ConsoleAction::kNextPart ? "next_part_requested"
                                             : "restart_requested",
             a == ConsoleAction::kReset      ? "reset requested: the e-stop cleared, devices reactivated"
             : a == ConsoleAction::kNextPart ? "the batch's next part (the control thread rebuilds the scene)"
                                             : "the scene restarts (the control thread rebuilds it)",
             m.client);
        live_.request(a);
        return;
      case ConsoleAction::kTaskStart:
      case ConsoleAction::kTaskPause:
      case ConsoleAction::kTaskResume:
      case ConsoleAction::kTaskConfirm:
      case ConsoleAction::kTaskTakeOver:
      case ConsoleAction::kTaskHandBack:
      case ConsoleAction::kTaskStepDone:
      case ConsoleAction::kTaskSkip: {
        // Pausing only stops the stage: anyone may (as the e-stop); the rest needs control.
        if (a != ConsoleAction::kTaskPause && m.client != controller) {
          tell(m.client, StatusLevel::kWarning, "control: take control first; action ignored", "refused",
               "control");
          return;
        }
        if (const std::string why = task_action_refusal(a, live_.status().task); !why.empty()) {
          tell(m.client, StatusLevel::kWarning, why, "refused", "task");
          return;
        }
        note(EventLevel::kInfo, "task_action", task_action_name(a), m.client);
        if (!live_.push_task_action(task_action(a)))
          tell(m.client, StatusLevel::kWarning, "task: the loop is busy; action dropped", "refused", "task");
        return;
      }
    }
  } catch (const Error& e) {
    // The status names what it refuses (its id is the offending message's topic), so a client
    // can tell which of its messages it concerns.
    tell(m.client, StatusLevel::kError, e.what(), "refused", std::string(m.topic.substr(0, 80)));
  }
}

void ConsoleServer::on_disconnect(server::ClientId client) {
  server::ClientId expected = client;
  if (controller_.compare_exchange_strong(expected, 0)) {
    // Nobody controls: the loop's watchdog sees stale commands and the stage holds.
    live_.set_console_in_control(false);
    note(EventLevel::kInfo, "control_released", "nobody controls: the stage holds", client);
  }
}

}  // namespace mc::live
