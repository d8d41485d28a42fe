#pragma once
// The small camera the tracking tests share: a 320 x 256 sensor behind the 10x objective (the
// physics does not depend on the pixel count), and the thickness of the part they track.

#include "microcobot/imaging/camera_params.h"

namespace mc::vision::testing {

inline constexpr int kW = 320, kH = 256;
inline constexpr double kTop = 100e-6;  ///< the tracked part's top: the substrate out of focus

inline imaging::CameraParams small_camera() {
  imaging::CameraParams c;
  c.objective = imaging::objective_by_name("10x");
  c.sensor.width_px = kW;
  c.sensor.height_px = kH;
  return c;
}

}  // namespace mc::vision::testing
