#pragma once
/// @file
/// The vendor-protocol clients (the GCS 2.0 and ANC300 twins, twins/): what a client asked,
/// taken on the operator tick (a heartbeat-guarded goal or a run of open-loop steps), and what
/// it reads back (positions, on-target after the settle window, stepping), published for its
/// threads. The heartbeat is the client's deadman: the source is active while its last command
/// or heartbeat is at most `command_timeout_s` old, and it ranks below a console client in
/// control, the demo and a started task (LivePlatform's order).
///
/// Pose moves of the parallel positioner queue here (at most kPoseQueue): the next starts when the
/// one under way has ended (Platform::start_pose_move, with the protocol's deadman); a stop clears
/// the queue, and so does losing control (stale, outranked, released, halted), which also holds
/// the positioner and marks the move under way interrupted. Its state leaves as one PositionerView
/// snapshot.

#include <array>
#include <atomic>
#include <cstdint>
#include <optional>

#include "microcobot/live/command_source.h"
#include "microcobot/live/protocol_command.h"
#include "microcobot/runtime/latest_value.h"
#include "microcobot/runtime/spsc_ring.h"

namespace mc::live {

struct ProtocolSourceParams {
  Eigen::Vector3d home_m = Eigen::Vector3d::Zero();  ///< the stage's home (the goals are relative to it)
  double command_timeout_s = 0.2;                    ///< the heartbeat's timeout
  double on_target_tolerance_m = 1e-6;               ///< an axis is on target within this...
  double settle_window_s = 0.02;                     ///< ...for this long
  double rotary_radius_m = 1.0;  ///< the rotary axis' contact radius (its tolerance as an arc)
};

class ProtocolSource final : public CommandSource {
 public:
  explicit ProtocolSource(const ProtocolSourceParams& params) : params_(params) {}

  /// A client's command (one producer thread: the protocol thread). Wait-free; false when the
  /// ring is full.
  bool push(const ProtocolCommand& c) noexcept { return ring_.push(c); }
  /// What the loop last published (without the console's and the e-stop's parts). Any thread.
  ProtocolView view() const noexcept;
  /// The positioner's newest snapshot (one reader thread: the protocol thread).
  PositionerView positioner_view() noexcept { return positioner_view_.read(); }
  static constexpr std::size_t kPoseQueue = 16;

  std::string_view name() const noexcept override { return "protocol"; }
  SourceRequest poll(const SourceTick& t) noexcept override;
  void drive(const SourceTick& t, teleop::ConsoleInput& in) noexcept override;
  void released(const SourceTick& t) noexcept override;
  void publish(const SourceTick& t) noexcept override;
  void reset() noexcept override;

 private:
  void stop_and_hold(platform::Platform& p) noexcept;
  void queue_pose(const ProtocolCommand& c) noexcept;
  /// Empties the pose queue; `rejected`: its moves are reported dropped (rejected_seq).
  void clear_pose_queue(bool rejected) noexcept;
  void publish_positioner(const SourceTick& t) noexcept;

  ProtocolSourceParams params_;
  runtime::SpscRing<ProtocolCommand> ring_{256};
  // Loop thread only.
  double last_t_ = -1e9, speed_m_s_ = 0.0, last_publish_t_ = 0.0;
  double theta_goal_rad_ = 0.0, theta_speed_rad_s_ = 0.0;
  bool holding_ = false, has_goal_ = false;
  std::array<double, 3> goal_m_{};
  std::array<double, 4> settled_s_{};  // X, Y, Z, theta
  // The step runs asked since the last tick, one per axis: runs on several axes play at once.
  std::array<std::optional<ProtocolCommand>, 4> pending_steps_{};
  std::uint64_t popped_seq_ = 0;
  std::array<std::optional<motion::PoseTrajectory>, kPoseQueue> pose_queue_{};
  std::array<std::uint64_t, kPoseQueue> pose_seq_{};
  std::size_t pose_head_ = 0, pose_count_ = 0;
  std::uint64_t pose_started_ = 0, pose_rejected_ = 0, pose_stop_ = 0, pose_interrupted_ = 0;
  bool pose_running_ = false;         // a pose move was under way at the last publish
  std::uint64_t platform_stops_ = 0;  // Platform::pose_moves_stopped() at the last publish
  runtime::LatestValue<PositionerView> positioner_view_;
  // Published for the protocol thread (X, Y, Z [m], theta [rad]).
  std::array<std::atomic<double>, 4> position_{};
  std::array<std::atomic<bool>, 4> on_target_{}, stepping_{};
  std::atomic<bool> driving_{false};
  std::atomic<std::uint64_t> refused_steps_{0}, applied_seq_{0};
};

}  // namespace mc::live
