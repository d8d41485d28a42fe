#pragma once
/// @file
/// What crosses between the real-time loop and the DDS link thread: one fixed-size, trivially
/// copyable sample per message, whatever its ROS 2 type (the loop never sees DDS types, strings
/// or sequences; it pushes and pops these through SpscRing).

#include <array>
#include <cstddef>
#include <cstdint>

namespace mc::net {

/// The coupling's channels, one per topic of the topic table (topics.h).
enum class Channel : std::uint8_t {
  kTarget,          ///< master -> slave: the slave's target position (m)
  kMeasuredPose,    ///< slave -> master: the slave's measured position (m)
  kContactForce,    ///< slave -> master: contact force on the gripper (N)
  kGripForce,       ///< slave -> master: grip force between the jaws (N)
  kGripperTarget,   ///< master -> slave: the gripper's target opening (m)
  kGripperOpening,  ///< slave -> master: the gripper's measured opening (m)
  kEstop,           ///< master -> slave: emergency stop (latched state, 0 or 1)
  kEngaged,         ///< master -> slave: the coupling is engaged (clutch; 0 or 1)
  /// slave -> master: the slave's device states (/diagnostics): `xyz` the lifecycles of axes x,
  /// y, z and `scalar` the gripper's, as devices::Lifecycle values (0 unconfigured, 1 inactive,
  /// 2 active, 3 fault)
  kSlaveDiagnostics,
  /// master -> slave: the energy the master's end has put into the coupling's channel since it
  /// started, one port per stage axis (J; time-domain passivity, passive_ports.h)
  kMasterPortEnergy,
  /// slave -> master: the same of the slave's end (J)
  kSlavePortEnergy,
  /// master -> slave: the energy the master's end has put into the gripper's port (J, in `xyz[0]`)
  kMasterGripperPortEnergy,
  /// slave -> master: the same of the slave's end (J, in `xyz[0]`)
  kSlaveGripperPortEnergy,
  /// master -> slave: the gripper's release burst on or off (latched state, 0 or 1; the slave's
  /// coupling passes it only while engaged and fresh: microworld/release.h, shake)
  kGripperShake,
};
inline constexpr std::size_t kChannelCount = 14;

/// One message. `xyz` holds a position (m), a force (N) or the energies of the ports (J) in the
/// stage frame; `scalar` the gripper opening (m) or a boolean (0/1). Unused fields are zero.
struct NetSample {
  Channel channel = Channel::kTarget;
  std::int64_t stamp_ns = 0;     ///< header stamp: ROS time (ns since the Unix epoch), >= 0
  std::int64_t received_ns = 0;  ///< steady clock when the link thread took it (0 when sending)
  std::array<double, 3> xyz{};   ///< m or N
  double scalar = 0.0;           ///< m, or 0/1
  /// Poses (target, measured): the gripper's yaw, the rotary axis' angle [rad], carried as the
  /// pose's orientation (a rotation about z); 0 on a stage without one.
  double yaw_rad = 0.0;

  /// Its transit (s): arrival (this end's steady clock) minus stamp (the sender's ROS time), the
  /// network's delay plus the clocks' offset (transit_estimate.h compares them).
  double transit_s() const noexcept { return 1e-9 * static_cast<double>(received_ns - stamp_ns); }
  /// Its arrival on this end's steady clock (s).
  double received_s() const noexcept { return 1e-9 * static_cast<double>(received_ns); }
};

/// The network side's refusal reasons (counted per reason, never applied).
enum class Rejection : std::uint8_t {
  kNone,
  kNonFinite,   ///< NaN or infinity in a value
  kOutOfRange,  ///< beyond the platform's limits (NetLimits)
  kBadStamp,    ///< nanosec >= 1e9 or a negative time
  kBadSize,     ///< a sequence of the wrong length (JointState)
};
inline constexpr std::size_t kRejectionCount = 5;

/// The bounds a sample from the network must respect before it may reach the loop.
struct NetLimits {
  double max_abs_position_m = 0.05;  ///< stage positions (the XYZ stage travels a few mm)
  double max_abs_force_N = 10.0;     ///< contact and grip forces
  double max_opening_m = 0.01;       ///< gripper opening, [0, max]
  /// A port's input energy, [0, max]: 1 kJ is 10 N pushed over 100 m, beyond any session.
  double max_port_energy_J = 1e3;
  void validate() const;
};

}  // namespace mc::net
