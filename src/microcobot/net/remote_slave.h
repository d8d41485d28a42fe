#pragma once
/// @file
/// The slave stage of a distributed platform as the master process sees it
/// (`microcobot serve --role master`): three position-controlled axes and a gripper whose far end
/// is the slave process, over the DDS link. They are one more implementation of the platform's
/// device interfaces (devices/device.h, docs/hardware.md): the master's platform runs its
/// masters and the teleoperation coupling as always and hands the coupling's targets to these
/// axes; the slave process's stage controller follows them.
///
///   slave tick (1 kHz)  command_target_m() x 3, command_opening_m()
///   every tick          the gripper's update(): the link's incoming ring drained into the latest
///                       measurements; once all three targets of a slave tick are in, the target
///                       pose and the gripper target are queued for the link thread (only when
///                       they were computed on fresh measurements: a slave that appears gets
///                       no target before the coupling has re-taken it from its position)
///   safe state          the e-stop topic latched on (reliable, transient local), the coupling's
///                       engaged flag off; activate() releases both
///
/// When no pose has come from the slave for `stale_timeout_s` (a dead or cut-off slave; a pose's
/// age counts from when it was measured, beyond the fastest delivery seen (transit_estimate.h),
/// so that poses queued while the cable was out do not look new when they arrive), DDS no
/// longer sees it (Link::peer_alive(): a state topic unmatched, its liveliness lost or its deadline
/// missed), or its /diagnostics report a device that is not active (its own e-stop, a fault), the
/// axes report stale measurements: the coupling disengages with zero force on the masters at
/// once, and re-engages at the slave's measured position when poses return (a restarted slave
/// does not jump). The contact force the coupling renders has come out of the channel through
/// this end's passivity controller (passive_ports.h). Everything on the loop path only pushes to
/// and pops from the link's rings.

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>

#include "microcobot/motion/rotary_axis.h"
#include "microcobot/net/link.h"
#include "microcobot/net/passive_ports.h"
#include "microcobot/net/transit_estimate.h"
#include "microcobot/net/wire_emulator.h"
#include "microcobot/platform/platform.h"

namespace mc::net {

struct RemoteSlaveParams {
  LinkConfig link;  ///< its role is forced to master
  /// No pose for this long and the slave counts as silent: 8 ms, so that the release (at the
  /// next tick) lands within 10 ms of the slave's silence.
  double stale_timeout_s = 0.008;
  /// Also require DDS's verdict on the peer (Link::peer_alive(): every state topic matched, alive
  /// and within its deadline). Off only for a peer that is not a whole end of the platform: one
  /// that publishes some of the state topics, or slower than their 10 ms deadline (a ROS 2 tool;
  /// the tests of the loop-time timeout alone). The loop-time timeout above applies either way.
  bool watch_dds = true;
  /// Time-domain passivity control at this end's ports (passive_ports.h); false: observed only.
  bool passivity = true;
  double sample_period_s = 1e-5;  ///< reported as the axes' drive period (the model's step)
  double max_voltage_V = 100.0;   ///< reported; the slave's amplifier applies its own
  /// The slave's rotary axis under the gripper (the platform's stage.rotary: its position on the
  /// master is the arc at its radius); disabled: the link carries no yaw and the master has none.
  motion::RotaryAxisParams rotary = without_rotary();
  static motion::RotaryAxisParams without_rotary() {
    motion::RotaryAxisParams r;
    r.enabled = false;
    return r;
  }
  /// The link emulator on what this end receives (wire_emulator.h); all zero: none. With
  /// jitter the timeout grows by twice the jitter (keep-latest lines then leave gaps that long).
  teleop::LinkParams emulate;
  void validate() const;
};

/// What the master knows of the slave (loop thread).
struct RemoteSlaveState {
  std::array<double, 3> position_m{};  ///< measured, stage coordinates
  double yaw_rad = 0.0;                ///< the rotary axis' measured angle
  /// On the gripper, world frame, as it comes out of the channel (after the passivity controller)
  std::array<double, 3> contact_force_N{};
  double grip_force_N = 0.0;
  double opening_m = 0.0;
  double age_s = 1e9;  ///< since the last pose (starts stale)
  /// The slave's devices (axes x, y, z, gripper) as its /diagnostics last reported them;
  /// unknown (Unconfigured) until the first report.
  std::array<devices::Lifecycle, 4> lifecycle{};
  bool slave_active() const {
    for (auto l : lifecycle)
      if (l != devices::Lifecycle::kActive) return false;
    return true;
  }
};

class RemoteSlave {
 public:
  /// Starts the link (throws mc::Error: parameters, DDS).
  explicit RemoteSlave(const RemoteSlaveParams& params);
  ~RemoteSlave();
  RemoteSlave(const RemoteSlave&) = delete;
  RemoteSlave& operator=(const RemoteSlave&) = delete;

  /// New devices for one platform build: the three axes and the gripper (views of this link,
  /// which must outlive them). The masters are not filled in.
  devices::DeviceSet make_devices();

  const Link& link() const { return *link_; }
  /// Poses flow and every slave device is active (a slave that faulted or e-stopped itself is
  /// as good as silent to the coupling: it lets go, and re-engages once the slave is reset).
  bool fresh() const noexcept {
    return state_.age_s <= stale_timeout_s_ && state_.slave_active() &&
           (!params_.watch_dds || link_->peer_alive());
  }
  const RemoteSlaveState& state() const noexcept { return state_; }
  /// Not for the loop (any thread): the lowest observed energy of this end's ports since the
  /// start (J; >= 0 up to rounding with passivity control) and what its controller dissipated.
  double min_observed_energy_J() const noexcept { return min_observed_J_.load(std::memory_order_relaxed); }
  double dissipated_energy_J() const noexcept { return dissipated_J_.load(std::memory_order_relaxed); }

  // The devices' side (loop thread).
  void set_target(int axis, double target_m, double velocity_m_s) noexcept;
  void set_gripper_target(double opening_m) noexcept { gripper_target_m_ = opening_m; }
  /// The gripper's release burst: sent on change (latched), as the e-stop.
  void set_gripper_shake(bool on) noexcept;
  void exchange(double dt_s) noexcept;
  /// Latches the e-stop on the slave (a device entered its safe state) or releases it.
  void set_estop(bool on) noexcept;

 private:
  void send(Channel c, const std::array<double, 3>& xyz, double scalar, double yaw_rad = 0.0) noexcept;
  void apply(const NetSample& s) noexcept;

  RemoteSlaveParams params_;
  std::unique_ptr<Link> link_;
  std::unique_ptr<WireEmulator> emulator_;  // null: no emulation
  double stale_timeout_s_ = 0.0;
  double now_s_ = 0.0;            // loop time, from the ticks' dt
  TransitEstimate pose_transit_;  // the poses' route: how late each one arrives
  RemoteSlaveState state_;
  std::array<double, 3> target_m_{};
  double target_yaw_rad_ = 0.0;  // the rotary axis' (its arc's angle)
  unsigned target_mask_ = 0;     // bit i: axis i's target of this slave tick is in (3: the rotary)
  bool targets_fresh_ = false;   // they were computed on fresh measurements
  double gripper_target_m_ = 0.0;
  int estop_sent_ = -1;  // -1: never sent
  int shake_sent_ = -1;  // the same for the gripper's burst
  // The channel's master end: the force received, the rate of the targets sent, the sessions.
  MasterPorts ports_;
  std::array<double, 3> received_contact_N_{};
  std::array<double, 3> sent_target_m_{}, target_rate_m_s_{};
  double received_grip_N_ = 0.0;  // and the gripper's port: the grip force, the opening target's rate
  double sent_gripper_m_ = 0.0, gripper_rate_m_s_ = 0.0;
  bool target_sent_ = false;  // in this session
  double since_sent_s_ = 0.0;
  bool was_fresh_ = false;
  std::atomic<double> min_observed_J_{0.0}, dissipated_J_{0.0};
};

}  // namespace mc::net
