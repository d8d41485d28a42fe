#include "vision_camera_options.h"

#include <cmath>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/core/error.h"

namespace mc::cli {

void add_camera_options(CLI::App& cmd, CameraOptions& o) {
  cmd.add_option("--scene", o.scene,
                 "pick-place (default), pin-in-hole, or a YAML file of the microworld's keys");
  cmd.add_option("--objective", o.objective, "Objective: 2x, 5x, 10x (default), 20x, 50x");
  cmd.add_option("--seed", o.seed, "Seed of the sensor noise (default 1)");
  cmd.add_option("--template-px", o.template_px, "Side of the tracked template [px] (default 96)")
      ->check(CLI::Range(8, 1024));
}

imaging::CameraParams camera_for(const CameraOptions& o) {
  imaging::CameraParams cam;
  try {
    cam.objective = imaging::objective_by_name(o.objective);
  } catch (const mc::UsageError& e) {
    throw mc::UsageError(std::string("--objective: ") + e.what());
  }
  return cam;
}

imaging::PixelRoi centred_roi(double u, double v, int side, const imaging::CameraParams& cam) {
  const imaging::PixelRoi roi{static_cast<int>(std::lround(u - 0.5 * (side - 1))),
                              static_cast<int>(std::lround(v - 0.5 * (side - 1))), side, side};
  if (roi.x < 0 || roi.y < 0 || roi.x + side > cam.sensor.width_px || roi.y + side > cam.sensor.height_px)
    throw mc::InvalidInput(
        fmt::format("--template-px {}: the template around the target ({:.0f}, {:.0f}) px "
                    "leaves the {}x{} frame",
                    side, u, v, cam.sensor.width_px, cam.sensor.height_px));
  return roi;
}

}  // namespace mc::cli
