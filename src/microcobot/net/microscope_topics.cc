#include "microcobot/net/microscope_topics.h"

#include <cmath>
#include <cstring>

#include "microcobot/net/ros_mapping.h"

namespace mc::net {

const char* to_string(MicroscopeRejection r) {
  switch (r) {
    case MicroscopeRejection::kNone:
      return "none";
    case MicroscopeRejection::kBadSize:
      return "names and positions do not pair up (velocity and effort must be empty)";
    case MicroscopeRejection::kUnknownJoint:
      return "a joint other than focus_z and objective_turret, or one named twice";
    case MicroscopeRejection::kNonFinite:
      return "a position is not finite";
    case MicroscopeRejection::kOutOfRange:
      return "focus beyond 1 m, or a turret position that is not a whole number in [0, 64)";
    case MicroscopeRejection::kBadStamp:
      return "a stamp with nanosec >= 1e9 or a negative time";
  }
  return "?";
}

void to_ros(const MicroscopeJoints& j, MicroscopeJointBuffer& buf, sensor_msgs_msg_dds__JointState_& m) {
  m = {};
  m.header_.stamp_ = to_ros_time(j.stamp_ns);
  m.header_.frame_id_ = const_cast<char*>("");  // joints: no frame (never written through)
  std::uint32_t n = 0;
  if (j.has_focus) {
    buf.name[n] = const_cast<char*>(kFocusJoint);
    buf.position[n++] = j.focus_z_m;
  }
  if (j.objective >= 0) {
    buf.name[n] = const_cast<char*>(kTurretJoint);
    buf.position[n++] = static_cast<double>(j.objective);
  }
  m.name_._length = m.name_._maximum = n;
  m.name_._buffer = buf.name;
  m.name_._release = false;
  m.position_._length = m.position_._maximum = n;
  m.position_._buffer = buf.position;
  m.position_._release = false;
}

MicroscopeRejection from_ros(const sensor_msgs_msg_dds__JointState_& m, MicroscopeJoints& out) {
  const std::uint32_t n = m.name_._length;
  if (n == 0 || n > 2 || m.position_._length != n || m.name_._buffer == nullptr ||
      m.position_._buffer == nullptr || m.velocity_._length != 0 || m.effort_._length != 0)
    return MicroscopeRejection::kBadSize;
  MicroscopeJoints j;
  for (std::uint32_t i = 0; i < n; ++i) {
    const char* name = m.name_._buffer[i];
    const double x = m.position_._buffer[i];
    if (name == nullptr) return MicroscopeRejection::kUnknownJoint;
    if (!std::isfinite(x)) return MicroscopeRejection::kNonFinite;
    if (std::strcmp(name, kFocusJoint) == 0 && !j.has_focus) {
      if (std::abs(x) > kMaxAbsFocus_m) return MicroscopeRejection::kOutOfRange;
      j.has_focus = true;
      j.focus_z_m = x;
    } else if (std::strcmp(name, kTurretJoint) == 0 && j.objective < 0) {
      if (x < 0.0 || x >= kMaxObjectives || x != std::floor(x)) return MicroscopeRejection::kOutOfRange;
      j.objective = static_cast<int>(x);
    } else {
      return MicroscopeRejection::kUnknownJoint;
    }
  }
  if (!from_ros_time(m.header_.stamp_, j.stamp_ns)) return MicroscopeRejection::kBadStamp;
  out = j;
  return MicroscopeRejection::kNone;
}

}  // namespace mc::net
