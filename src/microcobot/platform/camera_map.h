#pragma once
/// @file
/// The pixel <-> stage map the live vision uses: the objective's measured
/// calibration (`camera.calibrations`, written by `microcobot vision calibrate --save`), or
/// without one the objective's nominal map: its pixel size, the image's columns along stage x
/// and its rows down along -y, the stage's home where the camera's view centre puts it
/// (vision/renderer.h's u_of_x, v_of_y). Stage coordinates are the axes' positions from the
/// stage's home.

#include "microcobot/platform/platform_config.h"
#include "microcobot/vision/affine_calibration.h"

namespace mc::platform {

/// The map of objective `objective` (an index into camera.objectives); `calibrated` (optional)
/// says whether it is a measured one.
vision::AffineMap camera_stage_map(const PlatformConfig& config, int objective, bool* calibrated = nullptr);

/// The map's object-side pixel size [m]: the square root of its area scale.
double map_m_per_px(const vision::AffineMap& map);

}  // namespace mc::platform
