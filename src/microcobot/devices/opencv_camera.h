#pragma once
/// @file
/// A real camera through OpenCV's VideoCapture (the videoio module, with its V4L2, GStreamer and
/// FFmpeg back-ends): `devices: {camera: {driver: opencv, source: ...}}` (docs/hardware.md).
/// OpenCV stays in one translation unit, opencv_camera.cc, built when CMake's MC_WITH_OPENCV is
/// on; without it the driver is absent and the configuration says so.

#include <memory>
#include <string>

#include "microcobot/devices/camera_device.h"

namespace mc::devices {

/// True when this build has the OpenCV camera driver.
bool opencv_camera_available();

/// A camera OpenCV opens from `source`: a device index ("0"), a device file ("/dev/video0"), a
/// video file (looped, played at the camera's frame rate) or a GStreamer pipeline (containing
/// '!', ending in an appsink). Frames are converted to the configured sensor: grey (8 bit) or
/// RGB when the source is in colour, resized to width_px x height_px when they differ.
/// Throws mc::InvalidParams when the build has no OpenCV; opening happens in open().
std::unique_ptr<FrameSource> make_opencv_camera(const std::string& source);

}  // namespace mc::devices
