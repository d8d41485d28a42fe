#pragma once
/// @file
/// The camera's frames on DDS as a ROS 2 image topic, so that a ROS 2 image viewer
/// (rqt_image_view, Foxglove over a ROS bridge) subscribes to the microscope:
///
///   /microcobot/slave/camera/image_raw/compressed   DDS rt/microcobot/slave/camera/image_raw/compressed
///   sensor_msgs::msg::dds_::CompressedImage_        format "jpeg", frame_id camera_optical_frame
///
/// QoS as ROS 2's sensor-data profile (rclcpp::SensorDataQoS): best effort, volatile, keep last
/// 1 (an image late is worth less than the next one). Stamps are the frame's mid-exposure in
/// live time, as on the console's /camera/image/compressed channel.
///
/// Runs on the camera thread (publish()); never on the loop. wanted() tells whether a reader has
/// matched, so that the camera forms frames only while somebody looks (ConsoleServer's demand).
#include <string_view>

#include <dds/dds.h>

#include "microcobot/devices/camera_frame.h"
#include "microcobot/net/participant.h"
#include "microcobot/net/topic_writer.h"

namespace mc::net {

inline constexpr std::string_view kCameraImageRosName = "/microcobot/slave/camera/image_raw/compressed";
inline constexpr std::string_view kCameraImageDdsName = "rt/microcobot/slave/camera/image_raw/compressed";
inline constexpr std::string_view kCameraImageTypeName = "sensor_msgs::msg::dds_::CompressedImage_";

class CameraImagePublisher {
 public:
  /// A participant of its own on `domain_id` with the link's network configuration. Throws
  /// InvalidParams / ComputationFailed as Participant does.
  CameraImagePublisher(int domain_id, const NetworkConfig& network);
  CameraImagePublisher(const CameraImagePublisher&) = delete;
  CameraImagePublisher& operator=(const CameraImagePublisher&) = delete;

  /// Whether a reader is matched (any thread).
  bool wanted() const;
  /// Writes `frame`'s JPEG stamped `t_s` (live time). Frames without a JPEG are skipped.
  /// Returns false when DDS refused the write (counted in failures()).
  bool publish(const devices::CameraFrame& frame, double t_s);

  std::uint64_t published() const { return writer_.written(); }
  std::uint64_t failures() const { return writer_.failures(); }

 private:
  Participant participant_;
  TopicWriter writer_;  // written on the camera thread
};

}  // namespace mc::net
