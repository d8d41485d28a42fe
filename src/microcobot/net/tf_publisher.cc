#include "microcobot/net/tf_publisher.h"

#include <array>
#include <string>

#include "microcobot/live/camera_messages.h"
#include "ros2_messages.h"

namespace mc::net {

namespace {

// As tf2_ros's TransformBroadcaster: reliable, volatile, keep last 100.
QosPtr tf_qos() {
  QosPtr qos(dds_create_qos());
  dds_qset_reliability(qos.get(), DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_durability(qos.get(), DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos.get(), DDS_HISTORY_KEEP_LAST, 100);
  return qos;
}

}  // namespace

TfPublisher::TfPublisher(int domain_id, const NetworkConfig& network, const platform::TelemetrySchema& schema,
                         const motion::ParallelGeometryParams* positioner)
    : participant_(domain_id, network),
      frames_(schema, positioner),
      writer_(participant_.handle(), tf2_msgs_msg_dds__TFMessage__desc, kTfDdsName, tf_qos().get(),
              "frames") {}

bool TfPublisher::publish(const platform::TelemetrySample& s) {
  live::FrameTransforms f;
  const std::size_t n = frames_.transforms(s, f);
  const live::RosTime stamp = live::ros_time(s[0]);
  // The frame names as C strings for the generated type (string views of literals: terminated).
  std::array<geometry_msgs_msg_dds__TransformStamped_, live::kMaxRobotFrames> list{};
  for (std::size_t i = 0; i < n; ++i) {
    geometry_msgs_msg_dds__TransformStamped_& t = list[i];
    t.header_.stamp_.sec_ = stamp.sec;
    t.header_.stamp_.nanosec_ = stamp.nanosec;
    // The generated type holds non-const pointers; dds_write only reads them.
    t.header_.frame_id_ = const_cast<char*>(f[i].parent.data());
    t.child_frame_id_ = const_cast<char*>(f[i].child.data());
    t.transform_.translation_ = {f[i].x_m, f[i].y_m, f[i].z_m};
    t.transform_.rotation_ = {f[i].qx, f[i].qy, f[i].qz, f[i].qw};
  }
  tf2_msgs_msg_dds__TFMessage_ m{};
  m.transforms_._buffer = list.data();
  m.transforms_._length = static_cast<std::uint32_t>(n);
  m.transforms_._maximum = m.transforms_._length;
  m.transforms_._release = false;
  return writer_.write(&m);
}

}  // namespace mc::net
