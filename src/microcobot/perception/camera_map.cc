#include "microcobot/perception/camera_map.h"

#include <cmath>

namespace mc::perception {

vision::AffineMap camera_stage_map(const CameraRig& rig, int objective, bool* calibrated) {
  if (const vision::StageCalibration* c = rig.camera.calibration(objective)) {
    if (calibrated) *calibrated = true;
    return c->map();
  }
  if (calibrated) *calibrated = false;
  const double px = rig.camera.m_per_px(objective);
  const auto& s = rig.camera.sensor;
  vision::AffineMap m;
  m.A << 1.0 / px, 0.0, 0.0, -1.0 / px;
  m.b = {(rig.stage_home_m.x() - rig.camera.view_center_x_m) / px + 0.5 * (s.width_px - 1),
         0.5 * (s.height_px - 1) - (rig.stage_home_m.y() - rig.camera.view_center_y_m) / px};
  return m;
}

double map_m_per_px(const vision::AffineMap& map) { return 1.0 / std::sqrt(std::abs(map.A.determinant())); }

}  // namespace mc::perception
