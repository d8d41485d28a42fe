#pragma once
/// @file
/// Our samples (net_sample.h) to and from the ROS 2 message types (ros2_messages.idl). SI units
/// on both sides (ROS 2's REP 103): positions in m, forces in N, openings in m; stamps are ROS
/// time, builtin_interfaces/Time {sec, nanosec}. Samples from the network are checked before they
/// are accepted: finite, within NetLimits, a valid stamp, sequences of the expected length;
/// anything else is refused with its reason.
///
/// The outgoing messages point at static strings (frame ids, joint names) and at storage the
/// caller owns (JointStateBuffer): filling one never allocates.

#include <cstdint>

#include "microcobot/net/net_sample.h"
#include "ros2_messages.h"

namespace mc::net {

/// Frame of positions and forces: the stage's frame (the XYZ stick-slip positioner).
inline constexpr const char* kStageFrame = "microcobot_stage";
/// JointState's joint name of the gripper opening.
inline constexpr const char* kGripperJoint = "gripper_opening";

/// ns since the epoch -> Time (nanosec in [0, 1e9)). Negative times are clamped to 0.
builtin_interfaces_msg_dds__Time_ to_ros_time(std::int64_t stamp_ns);
/// Time -> ns since the epoch; false when nanosec >= 1e9 or sec < 0.
bool from_ros_time(const builtin_interfaces_msg_dds__Time_& t, std::int64_t& stamp_ns);

void to_ros(const NetSample& s, geometry_msgs_msg_dds__PoseStamped_& m);
void to_ros(const NetSample& s, geometry_msgs_msg_dds__WrenchStamped_& m);
/// The ports' energies (J) of the time-domain passivity control, one per stage axis.
void to_ros(const NetSample& s, geometry_msgs_msg_dds__Vector3Stamped_& m);
void to_ros(const NetSample& s, std_msgs_msg_dds__Bool_& m);

/// The storage a JointState of one joint points at.
struct JointStateBuffer {
  char* name[1] = {const_cast<char*>(kGripperJoint)};
  double position[1] = {0.0};
};
void to_ros(const NetSample& s, JointStateBuffer& buf, sensor_msgs_msg_dds__JointState_& m);

/// The slave's devices on /diagnostics, in the order of NetSample's kSlaveDiagnostics fields.
inline constexpr const char* kSlaveDeviceNames[4] = {"microcobot/slave/axis_x", "microcobot/slave/axis_y",
                                                     "microcobot/slave/axis_z", "microcobot/slave/gripper"};
inline constexpr const char* kSlaveHardwareId = "microcobot_slave";

/// The storage a DiagnosticArray of the slave's four devices points at (static strings).
struct DiagnosticsBuffer {
  diagnostic_msgs_msg_dds__DiagnosticStatus_ status[4] = {};
};
/// One status per device: level OK (active), WARN (inactive), ERROR (fault), STALE
/// (unconfigured); the message is the lifecycle state ("active", ...), no key-values.
void to_ros(const NetSample& s, DiagnosticsBuffer& buf, diagnostic_msgs_msg_dds__DiagnosticArray_& m);

/// Each from_ros fills `out` (channel `c`) and returns kNone, or returns why it refused.
/// A pose's orientation is the gripper's yaw (the rotary axis): a unit rotation about z (an
/// all-zero quaternion reads as the identity); any other is refused (out of range). A wrench's
/// torque is ignored.
Rejection from_ros(const geometry_msgs_msg_dds__PoseStamped_& m, Channel c, const NetLimits& lim,
                   NetSample& out);
Rejection from_ros(const geometry_msgs_msg_dds__WrenchStamped_& m, Channel c, const NetLimits& lim,
                   NetSample& out);
/// Each energy finite, within [0, max_port_energy_J].
Rejection from_ros(const geometry_msgs_msg_dds__Vector3Stamped_& m, Channel c, const NetLimits& lim,
                   NetSample& out);
/// Exactly one position; velocity and effort empty or of length one (and finite).
Rejection from_ros(const sensor_msgs_msg_dds__JointState_& m, Channel c, const NetLimits& lim,
                   NetSample& out);
Rejection from_ros(const std_msgs_msg_dds__Bool_& m, Channel c, NetSample& out);
/// Exactly the four statuses of kSlaveDeviceNames, in order, each message a lifecycle state's
/// name whose level matches it.
Rejection from_ros(const diagnostic_msgs_msg_dds__DiagnosticArray_& m, Channel c, NetSample& out);

}  // namespace mc::net
