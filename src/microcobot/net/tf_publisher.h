#pragma once
/// @file
/// The platform's frames on DDS as ROS 2's /tf, so that RViz, tf2 and Foxglove over a ROS bridge
/// see the tool, gripper, fingers and part move (the frame tree of live/robot_frames.h):
///
///   /tf    DDS rt/tf    tf2_msgs::msg::dds_::TFMessage_
///
/// Each message holds the tree of one telemetry sample, every transform stamped with the sample's
/// loop time (header.frame_id the parent frame). QoS as tf2_ros's TransformBroadcaster: reliable,
/// volatile, keep last 100.
///
/// Runs on the drain thread (publish()); never on the loop.
#include <cstdint>
#include <string_view>

#include <dds/dds.h>

#include "microcobot/live/robot_frames.h"
#include "microcobot/net/participant.h"
#include "microcobot/net/topic_writer.h"

namespace mc::net {

inline constexpr std::string_view kTfRosName = "/tf";
inline constexpr std::string_view kTfDdsName = "rt/tf";
inline constexpr std::string_view kTfTypeName = "tf2_msgs::msg::dds_::TFMessage_";

class TfPublisher {
 public:
  /// A participant of its own on `domain_id` with the link's network configuration; the frames
  /// from `schema`'s channels, and the parallel positioner's base, carriages and legs with its
  /// geometry `positioner` (live::RobotFrames). Throws InvalidParams / ComputationFailed as
  /// Participant does.
  TfPublisher(int domain_id, const NetworkConfig& network, const platform::TelemetrySchema& schema,
              const motion::ParallelGeometryParams* positioner = nullptr);
  TfPublisher(const TfPublisher&) = delete;
  TfPublisher& operator=(const TfPublisher&) = delete;

  /// Writes the frames of sample `s`. Returns false when DDS refused the write (counted).
  bool publish(const platform::TelemetrySample& s);

  std::uint64_t published() const { return writer_.written(); }
  std::uint64_t failures() const { return writer_.failures(); }

 private:
  Participant participant_;
  live::RobotFrames frames_;
  TopicWriter writer_;  // written on the drain thread
};

}  // namespace mc::net
