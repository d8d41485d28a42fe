#include "microcobot/net/positioner_pose_publisher.h"

#include <chrono>
#include <string>

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
               schema)) {
  const dds_entity_t pp = participant_.handle();
  dds_qos_t* qos = make_state_qos();
  topic_ = dds_create_topic(pp, &geometry_msgs_msg_dds__PoseStamped__desc,
                            std::string(kPositionerPoseTopic.dds_name).c_str(), qos, nullptr);
  if (topic_ >= 0) writer_ = dds_create_writer(pp, topic_, qos, nullptr);
  dds_delete_qos(qos);
  check_dds(topic_, "positioner: cannot create the pose topic");
  check_dds(writer_, "positioner: cannot create the pose writer");
}

// The participant's deletion (its destructor) deletes the topic and the writer with it.
PositionerPosePublisher::~PositionerPosePublisher() = default;

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
  m.header_.frame_id_ = const_cast<char*>(kPositionerBaseFrame.data());
  m.pose_.position_ = {p.x_m, p.y_m, p.z_m};
  m.pose_.orientation_ = {p.qx, p.qy, p.qz, p.qw};
  if (dds_write(writer_, &m) < 0) {
    ++failures_;
    return false;
  }
  ++published_;
  return true;
}

}  // namespace mc::net
