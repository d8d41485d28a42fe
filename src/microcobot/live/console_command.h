#pragma once
/// @file
/// What the operator console sends (docs/console.md, channels `/console/command` and
/// `/console/action`), parsed, checked and clamped before it may reach the loop:
/// types, finite numbers, ranges; anything else is refused with a one-line message naming the
/// field. The result is plain data, copied into the loop through a single-producer ring.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "microcobot/live/recorded_video.h"

namespace mc::live {

/// Limits every console command is clamped to (the platform's: the teleoperation's speed cap,
/// the stage's workspace in world coordinates, the gripper's stroke).
struct ConsoleLimits {
  double max_speed_m_s = 1e-3;
  std::array<double, 3> min_m = {-6e-3, -6e-3, -6e-3};
  std::array<double, 3> max_m = {6e-3, 6e-3, 6e-3};
  double max_opening_m = 600e-6;
  /// The rotary axis' travel and speed (both 0: there is none).
  double min_theta_rad = 0.0;
  double max_theta_rad = 0.0;
  double max_theta_speed_rad_s = 0.0;
  /// The microscope's focus travel (focal plane height) and turret positions (0: no camera).
  double focus_min_m = -0.5e-3;
  double focus_max_m = 2e-3;
  int objective_count = 0;
  /// The camera frame's last column and row (goal_px); 0 without a camera.
  std::array<double, 2> max_goal_px{};
  /// The camera's exposure and gain ranges.
  double min_exposure_s = 10e-6;
  double max_exposure_s = 33e-3;
  double min_gain = 1.0;
  double max_gain = 16.0;
  /// Whether the platform has a parallel positioner (`positioner: parallel`): pose_goal, pose_jog;
  /// and its moves' speeds (motion::PoseMoveLimits), a jog's bounds.
  bool has_positioner = false;
  double pose_max_speed_m_s = 0.0;
  double pose_max_angular_speed_rad_s = 0.0;
};

/// The console's continuous command (sent at ~30 Hz by the client in control: also its
/// heartbeat for the watchdog).
struct ConsoleCommand {
  bool deadman = false;
  std::array<double, 3> velocity_m_s{};  ///< joystick/keyboard/gamepad stage velocity
  bool has_goal = false;                 ///< click-to-go
  std::array<double, 3> goal_m{};        ///< world coordinates (the telemetry's)
  double goal_speed_m_s = 100e-6;
  /// Click-to-go on the camera's image (`stage.xy_sensor: vision`): the pixel the
  /// tool point is to be brought to, in the full frame's pixels (a binned preview's scaled up).
  bool has_goal_px = false;
  std::array<double, 2> goal_px{};
  bool has_gripper = false;
  double gripper_opening_m = 0.0;
  /// The gripper's release burst while true (microworld/release.h, shake): with the deadman and
  /// an opening, like every gripper command.
  bool gripper_shake = false;
  /// The rotary axis: to a yaw (the gripper's, world frame), or at the dial's rate; with the deadman.
  bool has_theta_goal = false;
  double theta_goal_rad = 0.0;
  double theta_rate_rad_s = 0.0;
  /// The microscope: focal plane height to go to, objective to turn in, the camera's
  /// exposure and gain. Each optional; they need control but not the deadman (nothing of the
  /// slave moves).
  bool has_focus = false;
  double focus_z_m = 0.0;
  int objective = -1;       ///< -1: unchanged
  double exposure_s = 0.0;  ///< 0: unchanged
  double gain = 0.0;        ///< 0: unchanged
  /// The parallel positioner to a pose, with the deadman: its platform {P} in its home frame {H},
  /// x, y, z [m] and rx, ry, rz [rad] with R = Rz(rz) Ry(ry) Rx(rx) (the telemetry's positioner
  /// channels). Reachability is checked where the move is planned (console_pose_goal.h).
  bool has_pose_goal = false;
  std::array<double, 6> pose_goal{};
  /// The parallel positioner jogged while the command says so, with the deadman: vx, vy, vz
  /// [m/s] of its platform's origin and wx, wy, wz [rad/s] about it, in {H} (ConsoleSource: the
  /// positioner follows a target a quarter of a second ahead; live/console_source.h).
  bool has_pose_jog = false;
  std::array<double, 6> pose_jog{};
  /// When the server received it (steady clock, ns; 0: unknown): the loop measures the
  /// command-to-target latency from it.
  std::int64_t received_ns = 0;
};

/// One-shot actions of `/console/action`.
enum class ConsoleAction {
  kEstop,           ///< every device to its safe state, latched
  kReset,           ///< clear a latched e-stop: devices reconfigured and activated
  kTakeControl,     ///< this client becomes the controlling one
  kReleaseControl,  ///< this client observes again
  kDemo,            ///< restart the scene with the scripted operator (the pick-and-place)
  kRestart,         ///< restart the scene, console in control
  kRecordStart,     ///< start an MCAP recording in --out
  kRecordStop,
  kVisionTare,  ///< force by vision's tare: nothing is between the fingers (the controlling client)
  /// The batch's next part (`serve --cell`): the scene rebuilt on it, its task not started (after
  /// the last part, the first again). The controlling client, as Restart.
  kNextPart,
  /// The PiezoGripper's tips levelled by touch (Platform::start_tip_levelling): the controlling
  /// client, running while it holds the deadman.
  kLevelTips,
  // The supervised task (`serve --cell`, live_task.h): its controls, in TaskAction's order.
  kTaskStart,
  kTaskPause,
  kTaskResume,
  kTaskConfirm,
  kTaskTakeOver,
  kTaskHandBack,  ///< this step again, from where the stage is
  kTaskStepDone,  ///< hand back: the operator did this step, the next one
  kTaskSkip,
};

/// Whether `a` is one of the task's controls.
inline bool is_task_action(ConsoleAction a) {
  return static_cast<int>(a) >= static_cast<int>(ConsoleAction::kTaskStart);
}

/// Parses `{"deadman": bool, "velocity_m_s": [vx, vy, vz], "goal_m": [x, y, z] (optional),
/// "goal_px": [u, v] (optional: a camera pixel, within the frame), "goal_speed_m_s": v (optional),
/// "gripper_opening_m": o (optional), "theta_goal_rad": a, "theta_rate_rad_s": w (optional: the rotary
/// axis; refused without one), "focus_z_m": z, "objective": i, "exposure_s": e, "gain": g (optional;
/// the microscope), "pose_goal": [x, y, z, rx, ry, rz] or "pose_jog": [vx, vy, vz, wx, wy, wz]
/// (optional, one or the other: the parallel positioner; refused without one)}`; unknown keys are
/// refused. Values are checked finite and clamped to `limits`; an
/// objective that is not on the turret is refused. Throws mc::InvalidInput
/// ("/console/command: velocity_m_s[1]: must be a finite number").
ConsoleCommand parse_console_command(std::string_view json, const ConsoleLimits& limits);

/// Parses `{"action": "estop" | "reset" | "take_control" | "release_control" | "demo" |
/// "restart" | "record_start" | "record_stop" | "vision_tare" | "next_part" | "level_tips" | "task_start" |
/// "task_pause" | "task_resume" | "task_confirm" | "task_take_over" | "task_hand_back" | "task_step_done" |
/// "task_skip"}`. Throws mc::InvalidInput.
ConsoleAction parse_console_action(std::string_view json);

/// An action with its options: record_start may say how the recording keeps the camera,
/// `{"action": "record_start", "video": "h264" | "jpeg" | "off"}` (unset: `serve --record-video`).
struct ActionRequest {
  ConsoleAction action = ConsoleAction::kEstop;
  std::optional<RecordedVideo> video;
};
/// Parses what parse_console_action() does, and record_start's "video". Throws mc::InvalidInput
/// ("/console/action: video: mp4 must be h264, jpeg or off").
ActionRequest parse_action_request(std::string_view json);

}  // namespace mc::live
