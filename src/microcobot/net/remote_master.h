#pragma once
/// @file
/// The master of a distributed platform as the slave process sees it
/// (`microcobot serve --role slave`): the source of the live platform's operator commands
/// (live/remote_link.h) in place of the console, over the DDS link. Each operator tick it
/// takes the master's latest target pose and gripper target into a console command (a
/// straight move to the target, at most at the coupling's console speed), reads the master's
/// e-stop and engaged flags, and publishes the slave's measured pose, contact and grip forces
/// and gripper opening, and its devices' states on /diagnostics (10 Hz, and at once on a change).
///
/// The master is fresh while it is engaged, its last target is at most `stale_timeout_s` old
/// (counted from when it was sent, beyond the fastest delivery seen (transit_estimate.h): targets
/// queued while the cable was out do not look new when they arrive)
/// and DDS sees it (Link::peer_alive(): matched, alive, within its deadlines).
/// A dead master holds the slave within 10 ms: the coupling disengages and the stage holds its
/// target. Its e-stop latches the slave's; releasing it resets it.
///
/// The targets go through a jitter buffer first (target_stream.h): the master's
/// motion interpolated `stream.delay_s` behind its stamps, late targets held, never jumped to.
/// The target leaves the channel through this end's passivity controller (passive_ports.h): the
/// stage's goal is the integral of the velocity the controller lets through towards the master's
/// target, which is the target itself unless the master's energy has not arrived yet (a contact
/// pressed before the master felt it); the goal then lags and catches up once it has.

#include <array>
#include <atomic>
#include <memory>

#include "microcobot/live/remote_link.h"
#include "microcobot/net/link.h"
#include "microcobot/net/passive_ports.h"
#include "microcobot/net/target_stream.h"
#include "microcobot/net/transit_estimate.h"
#include "microcobot/net/wire_emulator.h"

namespace mc::net {

struct RemoteMasterParams {
  LinkConfig link;  ///< its role is forced to slave
  /// A target older than this: the master is silent. 8 ms, so that the hold (at the next
  /// operator tick) lands within 10 ms of the master's death.
  double stale_timeout_s = 0.008;
  /// Also require DDS's verdict on the peer (Link::peer_alive(): every state topic matched, alive
  /// and within its deadline). Off only for a peer that is not a whole end of the platform: one
  /// that publishes some of the state topics, or slower than their 10 ms deadline (a ROS 2 tool;
  /// the tests of the loop-time timeout alone). The loop-time timeout above applies either way.
  bool watch_dds = true;
  std::array<double, 3> home_m{};  ///< the stage's home, world coordinates (targets are relative)
  double goal_speed_m_s = 1e-3;    ///< speed cap of the move to each target (the coupling caps too)
  /// The targets' jitter buffer (target_stream.h): look-ahead 2 ms (twice the 1 kHz period:
  /// loopback's jitter is below it), rejoining after a hold at 1 mm/s (the console's speed).
  /// With an emulated jitter (`emulate`) the look-ahead is raised to cover it.
  motion::SetpointStreamParams stream = default_stream();
  /// false: each target followed as it arrives (no buffer, for comparison).
  bool interpolate_targets = true;
  /// The slave's platform has the rotary axis: the master's target yaw is its goal (turned at the
  /// axis' own speed limit, with the master's engaged flag as the deadman).
  bool rotary = false;
  /// Time-domain passivity control at this end's ports (passive_ports.h); false: observed only.
  bool passivity = true;
  /// The link emulator on what this end receives (wire_emulator.h); all zero: none. With
  /// jitter the timeout grows by twice the jitter.
  teleop::LinkParams emulate;
  void validate() const;
  static motion::SetpointStreamParams default_stream() {
    motion::SetpointStreamParams p;
    p.delay_s = 2e-3;
    p.capacity = 64;
    p.max_velocity_m_s = 1e-3;
    return p;
  }
};

class RemoteMaster final : public live::RemoteLink {
 public:
  /// Starts the link (throws mc::Error: parameters, DDS).
  explicit RemoteMaster(const RemoteMasterParams& params);
  ~RemoteMaster() override;

  live::RemoteRequest poll(double t_s, live::ConsoleCommand& command) noexcept override;
  void publish(const platform::Platform& platform) noexcept override;

  const Link& link() const { return *link_; }
  /// Not for the loop (any thread): the lowest observed energy of this end's ports since the
  /// start (J; >= 0 up to rounding with passivity control) and what its controller dissipated.
  double min_observed_energy_J() const noexcept { return min_observed_J_.load(std::memory_order_relaxed); }
  double dissipated_energy_J() const noexcept { return dissipated_J_.load(std::memory_order_relaxed); }

 private:
  void send(Channel c, const std::array<double, 3>& xyz, double scalar, std::int64_t stamp_ns,
            double yaw_rad = 0.0) noexcept;
  void apply(const NetSample& s, double t_s, live::RemoteRequest& r) noexcept;

  RemoteMasterParams params_;
  std::unique_ptr<Link> link_;
  std::unique_ptr<WireEmulator> emulator_;  // null: no emulation
  double stale_timeout_s_ = 0.0;
  double last_target_t_ = -1e9;     // poll time at which the newest target was sent
  TransitEstimate target_transit_;  // the targets' route: how late each one arrives
  bool engaged_ = false;
  bool estop_ = false;
  bool shake_ = false;                                 // the master's gripper burst (latched)
  std::array<double, 4> states_sent_{-1, -1, -1, -1};  // lifecycles last put on /diagnostics
  int ticks_to_diagnostics_ = 0;
  // The channel's slave end: the master's latest target and the goal let through towards it
  // (both relative to home), the contact force of the last publish, the sessions.
  SlavePorts ports_;
  Axes3 asked_m_{}, goal_m_{}, contact_N_{};
  TargetStream targets_;
  double now_s_ = 0.0;  // this end's clock at the current poll (the stream's arrival times)
  bool has_target_ = false;
  // The gripper's port likewise: the opening asked, the one let through (from the gripper's
  // measured opening at the first publish), the grip force of the last publish.
  double asked_opening_m_ = 0.0, goal_opening_m_ = 0.0, grip_N_ = 0.0;
  double target_yaw_rad_ = 0.0;  // the master's target for the rotary axis
  bool has_gripper_target_ = false, opening_known_ = false;
  bool was_fresh_ = false;
  double last_poll_t_ = -1.0;
  std::atomic<double> min_observed_J_{0.0}, dissipated_J_{0.0};
};

}  // namespace mc::net
