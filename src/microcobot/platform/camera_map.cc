#include "microcobot/platform/camera_map.h"

#include <cmath>

namespace mc::platform {

vision::AffineMap camera_stage_map(const PlatformConfig& config, int objective, bool* calibrated) {
  if (const vision::StageCalibration* c = config.camera.calibration(objective)) {
    if (calibrated) *calibrated = true;
    return c->map();
  }
  if (calibrated) *calibrated = false;
  const double px = config.camera.m_per_px(objective);
  const auto& s = config.camera.sensor;
  vision::AffineMap m;
  m.A << 1.0 / px, 0.0, 0.0, -1.0 / px;
  m.b = {(config.stage.home_x_m - config.camera.view_center_x_m) / px + 0.5 * (s.width_px - 1),
         0.5 * (s.height_px - 1) - (config.stage.home_y_m - config.camera.view_center_y_m) / px};
  return m;
}

double map_m_per_px(const vision::AffineMap& map) { return 1.0 / std::sqrt(std::abs(map.A.determinant())); }

}  // namespace mc::platform
