#include "microcobot/net/positioner_pose_publisher.h"

#include <chrono>

#include "microcobot/core/error.h"
#include "microcobot/net/ros_mapping.h"
#include "microcobot/net/topics.h"
#include "ros2_messages.h"

namespace mc::net {

bool PositionerPosePublisher::fits(const platform::TelemetrySchema& schema) {
  return live::RobotFrames::fits(schema) && live::RobotFrames(schema).has_positioner();
}

PositionerPosePublisher::PositionerPosePublisher(int domain_id, const NetworkConfig& network,
                                                 const platform::TelemetrySchema& schema)
    : participant_(domain_id, network),
      frames_((require(fits(schema), "positioner pose", "needs a parallel positioner's telemetry channels"),
               schema)),
      writer_(participant_.handle(), geometry_msgs_msg_dds__PoseStamped__desc, kPositionerPoseTopic.dds_name,
              QosPtr(make_state_qos()).get(), "positioner pose") {}

bool PositionerPosePublisher::publish(const platform::TelemetrySample& s) {
  live::FrameTransforms f;
  const std::size_t n = frames_.transforms(s, f);
  std::size_t k = 0;  // the `world -> positioner` transform (fits(): the tree has it)
  while (k + 1 < n && f[k].child != "positioner") ++k;
  const live::FrameTransform& p = f[k];
  const std::int64_t ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                              std::chrono::system_clock::now().time_since_epoch())
                              .count();
  geometry_msgs_msg_dds__PoseStamped_ m{};
  m.header_.stamp_ = to_ros_time(ns);
  // The generated type holds a non-const pointer; dds_write only reads it (a literal: terminated).
  m.header_.frame_id_ = const_cast<char*>(kPositionerPoseFrame.data());
  m.pose_.position_ = {p.x_m, p.y_m, p.z_m};
  m.pose_.orientation_ = {p.qx, p.qy, p.qz, p.qw};
  return writer_.write(&m);
}

}  // namespace mc::net
