#pragma once
/// @file
/// The microscope's focus drive and objective turret on DDS (commands from the
/// console, the CLI, Python and the network alike), as ROS 2 joint states, so that the master process and any
/// ROS 2 node set and read them by name:
///
///   /microcobot/slave/microscope/command   sensor_msgs/msg/JointState   to the slave    on change
///       reliable, transient local, keep last 1 (a setting: a slave that starts later takes it)
///   /microcobot/slave/microscope/state     sensor_msgs/msg/JointState   from the slave  10 Hz, on change
///       reliable, volatile, keep last 1 (as /diagnostics)
///
/// Joints: `focus_z`, prismatic, the focal plane's height above the substrate [m] (REP 103); and
/// `objective_turret`, the turret's position: the objective's index (0-based) as a whole number.
/// A command names either joint or both, in any order, with one position each (velocity and
/// effort empty); the state names both. The slave's focus drive clamps a focus to its travel and
/// ignores an objective its turret does not have, as it does the console's.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "ros2_messages.h"

namespace mc::net {

inline constexpr std::string_view kMicroscopeCommandRosName = "/microcobot/slave/microscope/command";
inline constexpr std::string_view kMicroscopeCommandDdsName = "rt/microcobot/slave/microscope/command";
inline constexpr std::string_view kMicroscopeStateRosName = "/microcobot/slave/microscope/state";
inline constexpr std::string_view kMicroscopeStateDdsName = "rt/microcobot/slave/microscope/state";
inline constexpr const char* kFocusJoint = "focus_z";
inline constexpr const char* kTurretJoint = "objective_turret";
inline constexpr double kMicroscopeStateRate_Hz = 10.0;
/// Bounds of what a command may ask before the drive clamps it: a focal plane within 1 m, a
/// turret of at most 64 positions.
inline constexpr double kMaxAbsFocus_m = 1.0;
inline constexpr int kMaxObjectives = 64;

/// What a command asks (either part may be absent) or a state reports (both present).
struct MicroscopeJoints {
  bool has_focus = false;
  double focus_z_m = 0.0;
  int objective = -1;  ///< -1: not named
  std::int64_t stamp_ns = 0;
};

/// Why a command was refused.
enum class MicroscopeRejection : std::uint8_t {
  kNone,
  kBadSize,       ///< no joint, names and positions of different lengths, velocity or effort given
  kUnknownJoint,  ///< a name other than focus_z and objective_turret, or one named twice
  kNonFinite,
  kOutOfRange,  ///< |focus| > 1 m; a turret position not a whole number in [0, 64)
  kBadStamp,
};
inline constexpr std::size_t kMicroscopeRejectionCount = 6;
const char* to_string(MicroscopeRejection r);

/// The storage a JointState of the two joints points at (static names; no allocation).
struct MicroscopeJointBuffer {
  char* name[2] = {};
  double position[2] = {};
};
/// Fills `m` with the joints `j` has (both for a state), stamped `j.stamp_ns` (ROS time).
void to_ros(const MicroscopeJoints& j, MicroscopeJointBuffer& buf, sensor_msgs_msg_dds__JointState_& m);
/// Reads a command or a state; kNone and `out` filled, or why it was refused.
MicroscopeRejection from_ros(const sensor_msgs_msg_dds__JointState_& m, MicroscopeJoints& out);

}  // namespace mc::net
