#pragma once
/// @file
/// The parallel positioner's pose on DDS (`positioner: parallel`), so that a ROS 2 node follows the
/// part's carrier as it follows the stage's tool on /microcobot/slave/pose:
///
///   /microcobot/slave/positioner/pose   DDS rt/microcobot/slave/positioner/pose
///   geometry_msgs::msg::dds_::PoseStamped_   frame_id "world"
///
/// The pose is the platform {P} in the positioner's home frame {H} as its legs' sensors measure it (the
/// telemetry's positioner_* channels): position in metres, orientation R = Rz(rz) Ry(ry) Rx(rx) as
/// the unit quaternion q = qz(rz) qy(ry) qx(rx) (the `world -> positioner` transform of /tf,
/// live/robot_frames.h; the base is the world's origin). Published with every telemetry sample
/// (the state topics' 1 kHz) in the state profile's QoS (topics.h), stamped with ROS time (the
/// system clock when written, as the link's state topics). Not one of the coupling's topics: no
/// end of the link reads it (topics.h, kPositionerPoseTopic).
///
/// Runs on the drain thread (publish()); never on the loop.
#include <cstdint>

#include <dds/dds.h>

#include "microcobot/live/robot_frames.h"
#include "microcobot/net/participant.h"
#include "microcobot/net/topic_writer.h"
#include "microcobot/platform/telemetry_schema.h"

namespace mc::net {

/// The pose's header.frame_id: /tf's `world`, the positioner's home frame {H} (not
/// `positioner_base`, its base {B}, which /tf puts h + o below).
inline constexpr std::string_view kPositionerPoseFrame = "world";

class PositionerPosePublisher {
 public:
  /// Whether `schema` has the positioner's pose (a platform with `positioner: parallel`).
  static bool fits(const platform::TelemetrySchema& schema);
  /// A participant of its own on `domain_id` with the link's network configuration; the pose from
  /// `schema`'s channels. Throws InvalidParams when the schema has no positioner, InvalidParams /
  /// ComputationFailed as Participant does.
  PositionerPosePublisher(int domain_id, const NetworkConfig& network,
                          const platform::TelemetrySchema& schema);
  PositionerPosePublisher(const PositionerPosePublisher&) = delete;
  PositionerPosePublisher& operator=(const PositionerPosePublisher&) = delete;

  /// Writes the pose of sample `s`. Returns false when DDS refused the write (counted).
  bool publish(const platform::TelemetrySample& s);

  std::uint64_t published() const { return writer_.written(); }
  std::uint64_t failures() const { return writer_.failures(); }

 private:
  Participant participant_;
  live::RobotFrames frames_;
  TopicWriter writer_;  // written on the drain thread
};

}  // namespace mc::net
