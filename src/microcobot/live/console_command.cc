#include "microcobot/live/console_command.h"

#include <algorithm>
#include <cmath>

#include <nlohmann/json.hpp>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"

namespace mc::live {
namespace {

using nlohmann::json;

// `field` may be a key the client sent: escaped and cut (excerpt), so the error stays one line.
[[noreturn]] void refuse(const char* channel, const std::string& field, const std::string& what) {
  throw InvalidInput(std::string(channel) + ": " + excerpt(field) + ": " + what);
}

json parse_object(const char* channel, std::string_view text) {
  json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) refuse(channel, "payload", "is not valid JSON");
  if (!j.is_object()) refuse(channel, "payload", "must be a JSON object");
  return j;
}

double finite(const char* channel, const json& v, const std::string& field) {
  if (!v.is_number()) refuse(channel, field, "must be a number");
  const double x = v.get<double>();
  if (!std::isfinite(x)) refuse(channel, field, "must be a finite number");
  return x;
}

std::array<double, 3> vec3(const char* channel, const json& v, const std::string& field) {
  if (!v.is_array() || v.size() != 3) refuse(channel, field, "must be an array of 3 numbers");
  std::array<double, 3> out{};
  for (std::size_t i = 0; i < 3; ++i) out[i] = finite(channel, v[i], field + "[" + std::to_string(i) + "]");
  return out;
}

// The parallel positioner's six numbers (a pose, a twist); `names`: theirs and their units, for
// the error. Refused without the positioner.
std::array<double, 6> vec6(const char* channel, const json& v, const std::string& field, bool has_positioner,
                           const char* names) {
  if (!has_positioner) refuse(channel, field, "there is no parallel positioner (positioner: parallel)");
  if (!v.is_array() || v.size() != 6)
    refuse(channel, field, std::string("must be an array of 6 numbers ") + names);
  std::array<double, 6> out{};
  for (std::size_t i = 0; i < 6; ++i) out[i] = finite(channel, v[i], field + "[" + std::to_string(i) + "]");
  return out;
}

}  // namespace

ConsoleCommand parse_console_command(std::string_view text, const ConsoleLimits& limits) {
  constexpr const char* kChannel = "/console/command";
  const json j = parse_object(kChannel, text);
  ConsoleCommand c;
  for (const auto& [key, value] : j.items()) {
    if (key == "deadman") {
      if (!value.is_boolean()) refuse(kChannel, key, "must be true or false");
      c.deadman = value.get<bool>();
    } else if (key == "velocity_m_s") {
      c.velocity_m_s = vec3(kChannel, value, key);
    } else if (key == "goal_m") {
      c.goal_m = vec3(kChannel, value, key);
      c.has_goal = true;
    } else if (key == "goal_px") {
      if (!value.is_array() || value.size() != 2) refuse(kChannel, key, "must be an array of 2 numbers");
      for (std::size_t i = 0; i < 2; ++i) {
        c.goal_px[i] = finite(kChannel, value[i], key + "[" + std::to_string(i) + "]");
        if (c.goal_px[i] < 0.0 || c.goal_px[i] > limits.max_goal_px[i])
          refuse(kChannel, key + "[" + std::to_string(i) + "]",
                 limits.max_goal_px[i] <= 0.0
                     ? std::string("there is no camera")
                     : "must be within the frame [0, " +
                           std::to_string(static_cast<int>(limits.max_goal_px[i])) + "]");
      }
      c.has_goal_px = true;
    } else if (key == "goal_speed_m_s") {
      c.goal_speed_m_s = finite(kChannel, value, key);
      if (c.goal_speed_m_s <= 0.0) refuse(kChannel, key, "must be > 0");
    } else if (key == "gripper_opening_m") {
      c.gripper_opening_m = finite(kChannel, value, key);
      c.has_gripper = true;
    } else if (key == "gripper_shake") {
      if (!value.is_boolean()) refuse(kChannel, key, "must be true or false");
      c.gripper_shake = value.get<bool>();
    } else if (key == "theta_goal_rad" || key == "theta_rate_rad_s") {
      if (limits.max_theta_speed_rad_s <= 0.0) refuse(kChannel, key, "there is no rotary axis");
      const double v = finite(kChannel, value, key);
      if (key == "theta_goal_rad") {
        c.theta_goal_rad = std::clamp(v, limits.min_theta_rad, limits.max_theta_rad);
        c.has_theta_goal = true;
      } else {
        c.theta_rate_rad_s = std::clamp(v, -limits.max_theta_speed_rad_s, limits.max_theta_speed_rad_s);
      }
    } else if (key == "focus_z_m") {
      c.focus_z_m = std::clamp(finite(kChannel, value, key), limits.focus_min_m, limits.focus_max_m);
      c.has_focus = true;
    } else if (key == "objective") {
      if (!value.is_number_integer()) refuse(kChannel, key, "must be an integer");
      const auto i = value.get<std::int64_t>();
      if (i < 0 || i >= limits.objective_count)
        refuse(kChannel, key,
               limits.objective_count == 0
                   ? std::string("there is no camera")
                   : "must be within [0, " + std::to_string(limits.objective_count - 1) + "], not " +
                         std::to_string(i));
      c.objective = static_cast<int>(i);
    } else if (key == "exposure_s") {
      c.exposure_s = std::clamp(finite(kChannel, value, key), limits.min_exposure_s, limits.max_exposure_s);
    } else if (key == "pose_goal") {
      c.pose_goal = vec6(kChannel, value, key, limits.has_positioner, "[x, y, z, rx, ry, rz] (m, rad)");
      c.has_pose_goal = true;
    } else if (key == "pose_jog") {
      c.pose_jog = vec6(kChannel, value, key, limits.has_positioner, "[vx, vy, vz, wx, wy, wz] (m/s, rad/s)");
      c.has_pose_jog = true;
    } else if (key == "gain") {
      c.gain = std::clamp(finite(kChannel, value, key), limits.min_gain, limits.max_gain);
    } else {
      refuse(kChannel, key,
             "is not a known key (deadman, velocity_m_s, goal_m, goal_px, goal_speed_m_s, gripper_opening_m, "
             "gripper_shake, theta_goal_rad, theta_rate_rad_s, focus_z_m, objective, exposure_s, gain, "
             "pose_goal, pose_jog)");
    }
  }
  if (c.has_pose_goal && c.has_pose_jog)
    refuse(kChannel, "pose_jog", "cannot come with pose_goal (a jog or a goal, one at a time)");
  // Clamp to the platform's limits: a console can ask for anything, the stage gets what it can do.
  const double speed = std::hypot(c.velocity_m_s[0], c.velocity_m_s[1], c.velocity_m_s[2]);
  if (speed > limits.max_speed_m_s)
    for (double& v : c.velocity_m_s) v *= limits.max_speed_m_s / speed;
  c.goal_speed_m_s = std::min(c.goal_speed_m_s, limits.max_speed_m_s);
  for (std::size_t i = 0; i < 3; ++i) c.goal_m[i] = std::clamp(c.goal_m[i], limits.min_m[i], limits.max_m[i]);
  c.gripper_opening_m = std::clamp(c.gripper_opening_m, 0.0, limits.max_opening_m);
  // The jog's translation and rotation each within the positioner's move speeds.
  for (std::size_t part = 0; part < 2; ++part) {
    double* v = c.pose_jog.data() + 3 * part;
    const double cap = part == 0 ? limits.pose_max_speed_m_s : limits.pose_max_angular_speed_rad_s;
    const double magnitude = std::hypot(v[0], v[1], v[2]);
    if (magnitude > cap)
      for (int i = 0; i < 3; ++i) v[i] = v[i] * cap / magnitude;
  }
  return c;
}

ConsoleAction parse_console_action(std::string_view text) { return parse_action_request(text).action; }

ActionRequest parse_action_request(std::string_view text) {
  constexpr const char* kChannel = "/console/action";
  const json j = parse_object(kChannel, text);
  if (!j.contains("action")) refuse(kChannel, "payload", "must be {\"action\": NAME}");
  ActionRequest request;
  if (j.size() == 2 && j.contains("video") && j["action"] == "record_start") {
    const json& v = j["video"];
    request.video = v.is_string() ? parse_recorded_video(v.get<std::string>()) : std::nullopt;
    if (!request.video)
      refuse(kChannel, "video",
             excerpt(v.is_string() ? v.get<std::string>() : v.dump()) + " must be h264, jpeg or off");
  } else if (j.size() != 1) {
    refuse(kChannel, "payload", "must be {\"action\": NAME} (record_start may add \"video\")");
  }
  const json& a = j["action"];
  if (!a.is_string()) refuse(kChannel, "action", "must be a string");
  static constexpr std::pair<std::string_view, ConsoleAction> kNames[] = {
      {"estop", ConsoleAction::kEstop},
      {"reset", ConsoleAction::kReset},
      {"take_control", ConsoleAction::kTakeControl},
      {"release_control", ConsoleAction::kReleaseControl},
      {"demo", ConsoleAction::kDemo},
      {"restart", ConsoleAction::kRestart},
      {"record_start", ConsoleAction::kRecordStart},
      {"record_stop", ConsoleAction::kRecordStop},
      {"vision_tare", ConsoleAction::kVisionTare},
      {"next_part", ConsoleAction::kNextPart},
      {"level_tips", ConsoleAction::kLevelTips},
      {"task_start", ConsoleAction::kTaskStart},
      {"task_pause", ConsoleAction::kTaskPause},
      {"task_resume", ConsoleAction::kTaskResume},
      {"task_confirm", ConsoleAction::kTaskConfirm},
      {"task_take_over", ConsoleAction::kTaskTakeOver},
      {"task_hand_back", ConsoleAction::kTaskHandBack},
      {"task_step_done", ConsoleAction::kTaskStepDone},
      {"task_skip", ConsoleAction::kTaskSkip},
  };
  const std::string name = a.get<std::string>();
  for (const auto& [n, action] : kNames)
    if (n == name) {
      request.action = action;
      return request;
    }
  refuse(kChannel, "action",
         excerpt(name) +
             " must be one of estop, reset, take_control, release_control, demo, restart, record_start, "
             "record_stop, vision_tare, next_part, level_tips, task_start, task_pause, task_resume, "
             "task_confirm, task_take_over, task_hand_back, task_step_done, task_skip");
}

}  // namespace mc::live
