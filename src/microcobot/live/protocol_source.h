#pragma once
/// @file
/// The vendor-protocol clients (the GCS 2.0 and ANC300 twins, twins/): what a client asked,
/// taken on the operator tick (a heartbeat-guarded goal or a run of open-loop steps), and what
/// it reads back (positions, on-target after the settle window, stepping), published for its
/// threads. The heartbeat is the client's deadman: the source is active while its last command
/// or heartbeat is at most `command_timeout_s` old, and it ranks below a console client in
/// control, the demo and a started task (LivePlatform's order).

#include <array>
#include <atomic>
#include <cstdint>
#include <optional>

#include "microcobot/live/command_source.h"
#include "microcobot/live/protocol_command.h"
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

  std::string_view name() const noexcept override { return "protocol"; }
  SourceRequest poll(const SourceTick& t) noexcept override;
  void drive(const SourceTick& t, teleop::ConsoleInput& in) noexcept override;
  void released(const SourceTick& t) noexcept override;
  void publish(const SourceTick& t) noexcept override;
  void reset() noexcept override;

 private:
  void stop_and_hold(platform::Platform& p) noexcept;

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
  // Published for the protocol thread (X, Y, Z [m], theta [rad]).
  std::array<std::atomic<double>, 4> position_{};
  std::array<std::atomic<bool>, 4> on_target_{}, stepping_{};
  std::atomic<bool> driving_{false};
  std::atomic<std::uint64_t> refused_steps_{0}, applied_seq_{0};
};

}  // namespace mc::live
