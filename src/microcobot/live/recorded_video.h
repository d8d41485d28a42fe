#pragma once
/// @file
/// How a recording keeps the camera (`serve --record-video`, the console's
/// `{"action": "record_start", "video": ...}`; docs/console.md "Recordings"):
///
///   h264  /camera/video, foxglove.CompressedVideo (JSON): H.264 access units (live/h264_encoder.h),
///         a fraction of the JPEG frames' bytes (docs/benchmarks.md)
///   jpeg  /camera/image/compressed, sensor_msgs/msg/CompressedImage (CDR): each frame's JPEG, as
///         the console's channel sends it
///   off   no camera channel: a recording does not ask the camera for frames
///
/// With h264 and jpeg, /camera/camera_info and /camera/state accompany every frame.

#include <cstdint>
#include <optional>
#include <string_view>

namespace mc::live {

enum class RecordedVideo : std::uint8_t { kH264, kJpeg, kOff };

/// "h264", "jpeg" or "off".
constexpr std::string_view recorded_video_name(RecordedVideo v) {
  return v == RecordedVideo::kH264 ? "h264" : v == RecordedVideo::kJpeg ? "jpeg" : "off";
}

/// The format `name` names (nullopt: none).
constexpr std::optional<RecordedVideo> parse_recorded_video(std::string_view name) {
  for (RecordedVideo v : {RecordedVideo::kH264, RecordedVideo::kJpeg, RecordedVideo::kOff})
    if (recorded_video_name(v) == name) return v;
  return std::nullopt;
}

}  // namespace mc::live
