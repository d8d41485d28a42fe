#pragma once
/// @file
/// The console: the commands of the client that took control in the browser (joystick, keys,
/// gamepad, click-to-go, gripper, rotary dial, microscope), taken from the server's ring at the
/// operator tick. Its deadman is the client's; it is fresh while that client holds control and
/// its last command is at most `command_timeout_s` old. It is active while a client holds
/// control (or the task it supervises is started), on standby otherwise: the lowest-ranked
/// driver, whose input, not fresh, holds the stage when nobody drives.
///
/// The parallel positioner's go-to pose (console_pose_goal.h): moves planned and checked by the
/// server arrive through their own ring and start only while the console drives with its deadman;
/// its jog (a twist in the command) makes it follow a target streamed on the loop, under the same
/// deadman.
///
/// What the console supervises rides on its input: the cell's task (live_task.h) drives or
/// holds in its place once started, and with x and y positioned by vision
/// (`stage.xy_sensor: vision`) the positioner takes its goals and plays its joystick open loop.

#include <atomic>
#include <chrono>

#include "microcobot/live/command_source.h"
#include "microcobot/live/console_command.h"
#include "microcobot/live/console_pose_goal.h"
#include "microcobot/live/live_task.h"
#include "microcobot/perception/vision_positioner.h"
#include "microcobot/runtime/latest_value.h"
#include "microcobot/runtime/spsc_ring.h"
#include "microcobot/runtime/timing_stats.h"

namespace mc::live {

struct ConsoleSourceParams {
  Eigen::Vector3d home_m = Eigen::Vector3d::Zero();  ///< the stage's home (the task's frame)
  double command_timeout_s = 0.2;                    ///< the commands go stale after this long
  double max_theta_speed_rad_s = 0.0;                ///< the rotary axis' goal speed
  double t_offset_s = 0.0;  ///< live time at the scene's start (the positioner's clock)
};

class ConsoleSource final : public CommandSource {
 public:
  /// `task`, `positioner`: what the console supervises (null: none); not owned.
  ConsoleSource(const ConsoleSourceParams& params, LiveTask* task, perception::VisionPositioner* positioner)
      : params_(params), task_(task), positioner_(positioner) {}

  /// The controlling client's command (one producer thread: the server's). Wait-free.
  bool push(const ConsoleCommand& c) noexcept { return commands_.push(c); }
  /// Whether a client holds control (its commands count; otherwise the stage holds). Any thread.
  void set_in_control(bool in_control) noexcept { in_control_.store(in_control); }
  bool in_control() const noexcept { return in_control_.load(); }
  /// A pose move or stop of the parallel positioner (the server's thread, one producer; planned and
  /// checked there). Wait-free; false when the ring is full.
  bool push_pose_move(const ConsolePoseMove& m) noexcept { return pose_moves_.push(m); }
  /// What the loop last published of the positioner for the console. One reader: the server's thread.
  ConsolePoseView pose_view() noexcept { return pose_view_.read(); }
  /// Level the gripper's tips (the controlling client's Level tips; any thread): started at the
  /// next tick if the console drives then (Platform::start_tip_levelling's rules), else refused.
  void request_tip_levelling() noexcept { level_tips_.store(true, std::memory_order_relaxed); }
  /// A velocity run the positioner asks for (camera thread, one producer). Wait-free.
  bool push_vision(const perception::PositionerCommand& c) noexcept { return vision_.push(c); }
  /// The controlling client's commands are fresh (as of the last tick). Any thread.
  bool fresh() const noexcept { return fresh_.load(std::memory_order_relaxed); }
  /// Moves the command-to-target latencies measured since the last call into `stats` (one
  /// consumer thread).
  void drain_latencies(runtime::TimingStats& stats) noexcept;
  /// Live time at the scene's start (control thread, loop stopped).
  void set_time_offset(double t_offset_s) noexcept { params_.t_offset_s = t_offset_s; }

  std::string_view name() const noexcept override { return "console"; }
  SourceRequest poll(const SourceTick& t) noexcept override;
  void drive(const SourceTick& t, teleop::ConsoleInput& in) noexcept override;
  void publish(const SourceTick& t) noexcept override;
  void reset() noexcept override;

 private:
  /// With x and y positioned by vision: the positioner's runs and the joystick's played open
  /// loop while the console drives with its deadman. After the input is set.
  void vision_tick(platform::Platform& p, const runtime::TickInfo& t) noexcept;
  /// The parallel positioner's pose moves: the newest taken from the ring starts while the
  /// console drives with its deadman (a stop ends the move under way); else it is dropped.
  void pose_tick(platform::Platform& p) noexcept;
  /// The console's jog of the parallel positioner (ConsoleCommand::pose_jog): while it drives with
  /// its deadman, the positioner follows a target ahead of its reference at the jog's speeds;
  /// released, it holds where it is.
  void jog_tick(platform::Platform& p) noexcept;

  ConsoleSourceParams params_;
  LiveTask* task_;
  perception::VisionPositioner* positioner_;
  runtime::SpscRing<ConsoleCommand> commands_{256};
  runtime::SpscRing<perception::PositionerCommand> vision_{16};  // camera thread -> loop
  runtime::SpscRing<double> latencies_{4096};                    // loop -> status thread [s]
  runtime::SpscRing<ConsolePoseMove> pose_moves_{8};             // server thread -> loop
  runtime::LatestValue<ConsolePoseView> pose_view_;              // loop -> server thread
  std::atomic<bool> in_control_{false}, fresh_{false}, level_tips_{false};
  // Loop thread only.
  ConsoleCommand latest_;
  double last_command_t_ = -1e9;
  bool driving_ = false;                         // it holds control in this tick
  std::optional<ConsolePoseMove> pending_pose_;  // taken from the ring, not started yet
  std::uint64_t pose_handled_ = 0;
};

}  // namespace mc::live
