#include "microcobot/net/ros_mapping.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string_view>

#include "microcobot/core/error.h"

namespace mc::net {

namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;

void fill_header(std::int64_t stamp_ns, std_msgs_msg_dds__Header_& h) {
  h.stamp_ = to_ros_time(stamp_ns);
  // Never written through: the DDS serialiser only reads it.
  h.frame_id_ = const_cast<char*>(kStageFrame);
}

bool finite3(double x, double y, double z) {
  return std::isfinite(x) && std::isfinite(y) && std::isfinite(z);
}

bool within(double x, double y, double z, double bound) {
  return std::abs(x) <= bound && std::abs(y) <= bound && std::abs(z) <= bound;
}

Rejection check_vector(double x, double y, double z, double bound, const std_msgs_msg_dds__Header_& h,
                       Channel c, NetSample& out) {
  if (!finite3(x, y, z)) return Rejection::kNonFinite;
  if (!within(x, y, z, bound)) return Rejection::kOutOfRange;
  std::int64_t stamp = 0;
  if (!from_ros_time(h.stamp_, stamp)) return Rejection::kBadStamp;
  out = NetSample{};
  out.channel = c;
  out.stamp_ns = stamp;
  out.xyz = {x, y, z};
  return Rejection::kNone;
}

}  // namespace

void NetLimits::validate() const {
  if (!(max_abs_position_m > 0) || !std::isfinite(max_abs_position_m))
    throw InvalidParams("max_abs_position_m", "must be a finite number > 0");
  if (!(max_abs_force_N > 0) || !std::isfinite(max_abs_force_N))
    throw InvalidParams("max_abs_force_N", "must be a finite number > 0");
  if (!(max_opening_m > 0) || !std::isfinite(max_opening_m))
    throw InvalidParams("max_opening_m", "must be a finite number > 0");
  if (!(max_port_energy_J > 0) || !std::isfinite(max_port_energy_J))
    throw InvalidParams("max_port_energy_J", "must be a finite number > 0");
}

builtin_interfaces_msg_dds__Time_ to_ros_time(std::int64_t stamp_ns) {
  if (stamp_ns < 0) stamp_ns = 0;
  constexpr std::int64_t kMaxNs =
      static_cast<std::int64_t>(std::numeric_limits<std::int32_t>::max()) * kNsPerS + (kNsPerS - 1);
  if (stamp_ns > kMaxNs) stamp_ns = kMaxNs;
  builtin_interfaces_msg_dds__Time_ t{};
  t.sec_ = static_cast<std::int32_t>(stamp_ns / kNsPerS);
  t.nanosec_ = static_cast<std::uint32_t>(stamp_ns % kNsPerS);
  return t;
}

bool from_ros_time(const builtin_interfaces_msg_dds__Time_& t, std::int64_t& stamp_ns) {
  if (t.sec_ < 0 || t.nanosec_ >= kNsPerS) return false;
  stamp_ns = static_cast<std::int64_t>(t.sec_) * kNsPerS + static_cast<std::int64_t>(t.nanosec_);
  return true;
}

void to_ros(const NetSample& s, geometry_msgs_msg_dds__PoseStamped_& m) {
  m = {};
  fill_header(s.stamp_ns, m.header_);
  m.pose_.position_.x_ = s.xyz[0];
  m.pose_.position_.y_ = s.xyz[1];
  m.pose_.position_.z_ = s.xyz[2];
  // The gripper's yaw (the rotary axis under it) as a rotation about z; 0: the identity.
  m.pose_.orientation_.z_ = std::sin(0.5 * s.yaw_rad);
  m.pose_.orientation_.w_ = std::cos(0.5 * s.yaw_rad);
}

void to_ros(const NetSample& s, geometry_msgs_msg_dds__WrenchStamped_& m) {
  m = {};
  fill_header(s.stamp_ns, m.header_);
  m.wrench_.force_.x_ = s.xyz[0];
  m.wrench_.force_.y_ = s.xyz[1];
  m.wrench_.force_.z_ = s.xyz[2];
}

void to_ros(const NetSample& s, geometry_msgs_msg_dds__Vector3Stamped_& m) {
  m = {};
  fill_header(s.stamp_ns, m.header_);
  m.vector_.x_ = s.xyz[0];
  m.vector_.y_ = s.xyz[1];
  m.vector_.z_ = s.xyz[2];
}

void to_ros(const NetSample& s, std_msgs_msg_dds__Bool_& m) { m.data_ = s.scalar != 0.0; }

void to_ros(const NetSample& s, JointStateBuffer& buf, sensor_msgs_msg_dds__JointState_& m) {
  m = {};
  fill_header(s.stamp_ns, m.header_);
  buf.name[0] = const_cast<char*>(kGripperJoint);
  buf.position[0] = s.scalar;
  m.name_._length = m.name_._maximum = 1;
  m.name_._buffer = buf.name;
  m.name_._release = false;
  m.position_._length = m.position_._maximum = 1;
  m.position_._buffer = buf.position;
  m.position_._release = false;
}

namespace {

// devices::Lifecycle's order: unconfigured, inactive, active, fault.
constexpr const char* kLifecycleNames[4] = {"unconfigured", "inactive", "active", "fault"};
constexpr std::uint8_t kLifecycleLevels[4] = {3, 1, 0, 2};  // STALE, WARN, OK, ERROR

}  // namespace

void to_ros(const NetSample& s, DiagnosticsBuffer& buf, diagnostic_msgs_msg_dds__DiagnosticArray_& m) {
  m = {};
  fill_header(s.stamp_ns, m.header_);
  const double states[4] = {s.xyz[0], s.xyz[1], s.xyz[2], s.scalar};
  for (std::size_t i = 0; i < 4; ++i) {
    const auto k = static_cast<std::size_t>(std::clamp(states[i], 0.0, 3.0));
    auto& st = buf.status[i];
    st = {};
    st.level_ = kLifecycleLevels[k];
    st.name_ = const_cast<char*>(kSlaveDeviceNames[i]);
    st.message_ = const_cast<char*>(kLifecycleNames[k]);
    st.hardware_id_ = const_cast<char*>(kSlaveHardwareId);
  }
  m.status_._length = m.status_._maximum = 4;
  m.status_._buffer = buf.status;
  m.status_._release = false;
}

Rejection from_ros(const diagnostic_msgs_msg_dds__DiagnosticArray_& m, Channel c, NetSample& out) {
  if (m.status_._length != 4 || m.status_._buffer == nullptr) return Rejection::kBadSize;
  double states[4] = {};
  for (std::size_t i = 0; i < 4; ++i) {
    const auto& st = m.status_._buffer[i];
    if (st.name_ == nullptr || std::string_view(st.name_) != kSlaveDeviceNames[i]) return Rejection::kBadSize;
    int k = -1;
    for (int j = 0; j < 4; ++j)
      if (st.message_ != nullptr && std::string_view(st.message_) == kLifecycleNames[j]) k = j;
    if (k < 0 || st.level_ != kLifecycleLevels[k]) return Rejection::kOutOfRange;
    states[i] = k;
  }
  std::int64_t stamp = 0;
  if (!from_ros_time(m.header_.stamp_, stamp)) return Rejection::kBadStamp;
  out = NetSample{};
  out.channel = c;
  out.stamp_ns = stamp;
  out.xyz = {states[0], states[1], states[2]};
  out.scalar = states[3];
  return Rejection::kNone;
}

Rejection from_ros(const geometry_msgs_msg_dds__PoseStamped_& m, Channel c, const NetLimits& lim,
                   NetSample& out) {
  const auto& p = m.pose_.position_;
  const Rejection r = check_vector(p.x_, p.y_, p.z_, lim.max_abs_position_m, m.header_, c, out);
  if (r != Rejection::kNone) return r;
  // The orientation: the yaw of a rotation about z (a ROS tool's all-zero quaternion is the identity).
  const auto& q = m.pose_.orientation_;
  if (!std::isfinite(q.x_) || !std::isfinite(q.y_) || !std::isfinite(q.z_) || !std::isfinite(q.w_))
    return Rejection::kNonFinite;
  const double n2 = q.x_ * q.x_ + q.y_ * q.y_ + q.z_ * q.z_ + q.w_ * q.w_;
  if (n2 == 0.0) {
    out.yaw_rad = 0.0;
    return r;
  }
  if (std::abs(n2 - 1.0) > 1e-3 || std::abs(q.x_) > 1e-6 || std::abs(q.y_) > 1e-6)
    return Rejection::kOutOfRange;  // not a unit rotation about z: the stage turns about z only
  out.yaw_rad = 2.0 * std::atan2(q.z_, q.w_);
  if (out.yaw_rad > M_PI) out.yaw_rad -= 2.0 * M_PI;
  if (out.yaw_rad <= -M_PI) out.yaw_rad += 2.0 * M_PI;
  return r;
}

Rejection from_ros(const geometry_msgs_msg_dds__WrenchStamped_& m, Channel c, const NetLimits& lim,
                   NetSample& out) {
  const auto& f = m.wrench_.force_;
  return check_vector(f.x_, f.y_, f.z_, lim.max_abs_force_N, m.header_, c, out);
}

Rejection from_ros(const geometry_msgs_msg_dds__Vector3Stamped_& m, Channel c, const NetLimits& lim,
                   NetSample& out) {
  const auto& e = m.vector_;
  const Rejection r = check_vector(e.x_, e.y_, e.z_, lim.max_port_energy_J, m.header_, c, out);
  // Energies put into the channel only grow from zero.
  if (r == Rejection::kNone && (e.x_ < 0.0 || e.y_ < 0.0 || e.z_ < 0.0)) return Rejection::kOutOfRange;
  return r;
}

Rejection from_ros(const sensor_msgs_msg_dds__JointState_& m, Channel c, const NetLimits& lim,
                   NetSample& out) {
  if (m.position_._length != 1 || m.position_._buffer == nullptr) return Rejection::kBadSize;
  if (m.name_._length > 1 || m.velocity_._length > 1 || m.effort_._length > 1) return Rejection::kBadSize;
  const double x = m.position_._buffer[0];
  for (const auto* seq : {&m.velocity_, &m.effort_}) {
    if (seq->_length == 1 && (seq->_buffer == nullptr || !std::isfinite(seq->_buffer[0])))
      return Rejection::kNonFinite;
  }
  if (!std::isfinite(x)) return Rejection::kNonFinite;
  if (x < 0.0 || x > lim.max_opening_m) return Rejection::kOutOfRange;
  std::int64_t stamp = 0;
  if (!from_ros_time(m.header_.stamp_, stamp)) return Rejection::kBadStamp;
  out = NetSample{};
  out.channel = c;
  out.stamp_ns = stamp;
  out.scalar = x;
  return Rejection::kNone;
}

Rejection from_ros(const std_msgs_msg_dds__Bool_& m, Channel c, NetSample& out) {
  out = NetSample{};
  out.channel = c;
  out.scalar = m.data_ ? 1.0 : 0.0;
  return Rejection::kNone;
}

}  // namespace mc::net
