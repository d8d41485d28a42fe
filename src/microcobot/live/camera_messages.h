#pragma once
/// @file
/// The camera's frames as ROS 2 messages, for Foxglove / Lichtblick (channels with
/// encoding "cdr" and "ros2msg" schemas), the recordings (the same bytes in MCAP) and the
/// console page (which reads the CompressedImage's JPEG out of the CDR):
///
///   /camera/image/compressed  sensor_msgs/msg/CompressedImage  format "jpeg"
///   /camera/camera_info       sensor_msgs/msg/CameraInfo       K from the objective's scale
///   /camera/state             microcobot.CameraState (JSON)    objective, focus, exposure, gain,
///                                                              scale, view centre, timings
///   /camera/video             foxglove.CompressedVideo (JSON)  format "h264": the recordings'
///                                                              H.264 (live/recorded_video.h)
///
/// CDR as ROS 2 puts it on the wire (rmw_cyclonedds_cpp; what @foxglove/rosmsg2-serialization
/// reads): the 4-byte encapsulation header 00 01 00 00 (CDR, little-endian), then the fields in
/// the order of the .msg files, each aligned to its size counted from after the header; strings
/// as a uint32 length including the terminating NUL, then the bytes and the NUL; sequences as a
/// uint32 count then the elements; fixed arrays as their elements.
///
/// The camera model of CameraInfo: the microscope seen as a pinhole at the objective's working
/// distance W above the focal plane, so that the scale there is the objective's: a pixel spans
/// s = pixel pitch / M in the object, fx = fy = W / s, (cx, cy) the image's centre; no distortion
/// ("plumb_bob", d = 0), R the identity, P = [K | 0].

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "microcobot/devices/camera_frame.h"
#include "microcobot/perception/vision_grip_force.h"
#include "microcobot/vision/affine_calibration.h"

namespace mc::live {

inline constexpr std::string_view kCameraImageTopic = "/camera/image/compressed";
/// The same frames binned to the console's panel (live/camera_preview.h), same schema.
inline constexpr std::string_view kCameraPreviewTopic = "/camera/preview/compressed";
inline constexpr std::string_view kCameraInfoTopic = "/camera/camera_info";
inline constexpr std::string_view kCameraStateTopic = "/camera/state";
/// The recordings' H.264 frames (`serve --record-video h264`).
inline constexpr std::string_view kCameraVideoTopic = "/camera/video";
inline constexpr std::string_view kCameraFrameId = "camera_optical_frame";

/// The ros2msg schema texts (the .msg with its dependencies, as Foxglove expects).
std::string_view compressed_image_schema();
std::string_view camera_info_schema();
/// The JSON schema of /camera/state.
std::string camera_state_schema();
/// The JSON schema of foxglove.CompressedVideo (Foxglove's message schemas: timestamp {sec, nsec},
/// frame_id, data as base64, format).
std::string compressed_video_schema();

/// A loop time as a ROS time (sec, nanosec).
struct RosTime {
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;
};
RosTime ros_time(double t_s);

/// sensor_msgs/msg/CompressedImage of `frame`'s JPEG, stamped `stamp`, into `out` (replaced).
/// sensor_msgs/msg/CompressedImage of a JPEG (format "jpeg").
void encode_compressed_image(std::span<const std::uint8_t> jpeg, RosTime stamp, std::string& out);
void encode_compressed_image(const devices::CameraFrame& frame, RosTime stamp, std::string& out);
/// foxglove.CompressedVideo of one H.264 access unit (Annex B), format "h264", as JSON into `out`
/// (replaced): `{"timestamp": {"sec", "nsec"}, "frame_id", "data": base64 (RFC 4648), "format"}`.
void encode_compressed_video(std::span<const std::uint8_t> annexb, RosTime stamp, std::string& out);
/// sensor_msgs/msg/CameraInfo of `frame` (its objective's scale and working distance).
void encode_camera_info(const devices::CameraFrame& frame, RosTime stamp, std::string& out);
/// /camera/state's JSON of `frame`, with the pixel <-> stage calibration of its objective when
/// the configuration holds one ("calibration": px_per_m, offset_px, residual_rms_px; else null),
/// and the grip force seen in it when the platform measures one ("grip_vision": grip_force_N
/// (null: not measured in this frame), gap_m, state; else null).
std::string camera_state_json(const devices::CameraFrame& frame, double frame_rate_Hz, std::uint64_t dropped,
                              const vision::StageCalibration* calibration,
                              const perception::VisionGripStatus* grip = nullptr);

}  // namespace mc::live
