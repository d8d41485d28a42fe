#pragma once

/// The camera's latest full frame, kept for a lossless download (a microscopy lab's
/// snapshot): GET /camera/snapshot.tiff (a baseline TIFF, 16-bit for deeper sensors, the
/// object-side scale in its resolution tags for ImageJ/Fiji, the frame's /camera/state as its
/// ImageDescription) or /camera/snapshot.png, named after the objective and the frame's live
/// time. The console's JPEGs are for the eye; this is the frame as the sensor gave it.
///
/// The camera thread offers every frame it forms (a copy of its samples: 2.6 MB for a 12-bit
/// 1280 x 1024 frame); the HTTP thread takes the latest out under the lock and encodes it
/// outside it. Frames are formed only while someone watches the camera, so a snapshot is the
/// frame the operator sees.

#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include "microcobot/devices/camera_frame.h"
#include "microcobot/imaging/sensor_model.h"
#include "microcobot/server/foxglove_server.h"

namespace mc::live {

inline constexpr std::string_view kSnapshotPath = "/camera/snapshot";

class CameraSnapshot {
 public:
  /// Keeps `frame` (the latest), with its /camera/state JSON and live time. Camera thread.
  void offer(const devices::CameraFrame& frame, const std::string& state_json, double t_s);

  /// The answer to GET `path` when it is kSnapshotPath + ".tiff" or ".png" (nullopt: another
  /// path). 503 with a one-line reason before the first frame. Any thread.
  std::optional<server::HttpReply> reply(std::string_view path) const;

 private:
  struct Kept {
    imaging::Frame frame;  // grey samples (a colour frame: the mean of its channels)
    double m_per_px = 0.0;
    std::string objective, state;
    double t_s = 0.0;
    bool valid = false;
  };
  mutable std::mutex mutex_;
  Kept kept_;
};

}  // namespace mc::live
