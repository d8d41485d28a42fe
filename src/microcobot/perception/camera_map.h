#pragma once
/// @file
/// The pixel <-> stage map the live vision uses: the objective's measured
/// calibration (`camera.calibrations`, written by `microcobot vision calibrate --save`), or
/// without one the objective's nominal map: its pixel size, the image's columns along stage x
/// and its rows down along -y, the stage's home where the camera's view centre puts it
/// (imaging/renderer.h's u_of_x, v_of_y). Stage coordinates are the axes' positions from the
/// stage's home.

#include <Eigen/Core>

#include "microcobot/devices/camera_device.h"
#include "microcobot/vision/affine_calibration.h"

namespace mc::perception {

/// What the perception components know of the platform: the camera over the stage and the
/// gripper's fingers it looks at. The platform fills it from its configuration
/// (platform::camera_rig()).
struct CameraRig {
  devices::CameraDeviceParams camera;      ///< sensor, objectives, calibrations, view centre
  Eigen::Vector2d stage_home_m{0.0, 0.0};  ///< the stage's home (x, y) in the world [m]
  double finger_width_m = 0.0;             ///< a finger's width in the image plane [m]
  double finger_stiffness_N_m = 0.0;       ///< a finger's bending stiffness at its tip [N/m]
};

/// The map of objective `objective` (an index into camera.objectives); `calibrated` (optional)
/// says whether it is a measured one.
vision::AffineMap camera_stage_map(const CameraRig& rig, int objective, bool* calibrated = nullptr);

/// The map's object-side pixel size [m]: the square root of its area scale.
double map_m_per_px(const vision::AffineMap& map);

}  // namespace mc::perception
