#include "microcobot/studies/force_by_vision_run.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/imaging/png_file.h"
#include "microcobot/imaging/renderer.h"
#include "microcobot/microworld/piezo_gripper.h"
#include "microcobot/platform/camera_scene.h"

namespace mc::studies {

namespace vs = mc::vision;

void ForceSceneParams::validate() const {
  require(std::isfinite(finger_stiffness_N_m) && finger_stiffness_N_m > 0.0, "finger_stiffness_N_m",
          "must be finite and > 0", finger_stiffness_N_m);
  require(std::isfinite(part_width_m) && part_width_m >= 50e-6 && part_width_m <= 2e-3, "part_width_m",
          "must be within [50 um, 2 mm]", part_width_m);
  require(std::isfinite(force_N) && force_N > 0.0 && force_N <= 1.0, "force_N", "must be within (0, 1] N",
          force_N);
  require(std::isfinite(part_x_m) && std::isfinite(part_y_m), "part_x_m/part_y_m", "must be finite");
  require(loaded_frames >= 2 && loaded_frames <= 10000, "loaded_frames", "must be within [2, 10000]",
          loaded_frames);
  require(width_px >= 0 && height_px >= 0, "width_px/height_px", "must be >= 0 (0: the sensor's)");
  tracker.validate();
}

ForceSceneResult run_force_scene(const ForceSceneParams& p) {
  p.validate();
  platform::PlatformConfig config;
  auto& world = config.world;
  world.part_side_m = p.part_width_m;
  world.gripper.finger_stiffness_N_m = p.finger_stiffness_N_m;
  world.gripper.max_opening_m = std::max(world.gripper.max_opening_m, p.part_width_m + 100e-6);
  const microworld::PiezoGripperParams& g = world.gripper;
  const double w = p.part_width_m;
  const double o = w - 2.0 * p.force_N / p.finger_stiffness_N_m;  // the free opening squeezing F
  require(o >= g.min_opening_m, "force_N",
          fmt::format("needs a free opening of {:.1f} um, below the gripper's {:.1f} um: at most k w / 2 = "
                      "{:.3g} mN on this part",
                      o * 1e6, g.min_opening_m * 1e6, 0.5e3 * p.finger_stiffness_N_m * (w - g.min_opening_m)),
          p.force_N);
  ForceSceneResult r;
  // The simulation's own force law and what it shows: the fingers at the part's faces.
  microworld::PiezoGripperState squeezed;
  squeezed.free_opening_m = o;
  r.true_force_N = microworld::grip_force_N(g, squeezed, w);
  r.true_deflection_m = r.true_force_N / p.finger_stiffness_N_m;

  imaging::CameraParams cam;
  cam.objective = imaging::objective_by_name(p.objective);
  if (p.width_px > 0) cam.sensor.width_px = p.width_px;
  if (p.height_px > 0) cam.sensor.height_px = p.height_px;
  cam.view_center_x_m = p.part_x_m;
  cam.view_center_y_m = p.part_y_m;
  imaging::Renderer renderer(cam);
  platform::CameraScenePose pose;
  pose.part_x_m = pose.tool_x_m = p.part_x_m;
  pose.part_y_m = pose.tool_y_m = p.part_y_m;
  pose.part_z_m = pose.tool_z_m = 0.5 * world.height_m();  // the tips at the part's mid-height
  imaging::CameraControls controls = renderer.default_controls();
  controls.focus_z_m = pose.tool_z_m;
  imaging::SceneSnapshot scene;
  imaging::Frame frame;
  std::uint64_t index = 0;
  const auto render_at = [&](double opening_m) {
    pose.opening_m = opening_m;
    platform::fill_camera_scene(config, pose, scene);
    scene.substrate.texture_seed = p.texture_seed;
    renderer.render(scene, controls, p.seed, index++, frame);
  };

  // Templates on the tips, fully open (60 um wider than the part): each finger's outer half and
  // its end, with 12 um of background beyond them; the jaw side, where the part will touch, left out.
  constexpr double kFingerWidth = 40e-6, kMargin = 12e-6, kAlong = 30e-6;  // fill_camera_scene's finger
  const double o0 = w + 60e-6;
  render_at(o0);
  const double tip_y = p.part_y_m - 0.5 * kFingerWidth;
  const auto roi_between = [&](double x0, double x1) {
    const double u0 = renderer.u_of_x(std::min(x0, x1)), u1 = renderer.u_of_x(std::max(x0, x1));
    const double v0 = renderer.v_of_y(tip_y + kAlong), v1 = renderer.v_of_y(tip_y - kMargin);
    return imaging::PixelRoi{static_cast<int>(std::lround(u0)), static_cast<int>(std::lround(v0)),
                             static_cast<int>(std::lround(u1 - u0)), static_cast<int>(std::lround(v1 - v0))};
  };
  const double right_tip = p.part_x_m + 0.5 * (o0 + kFingerWidth);
  const double left_tip = p.part_x_m - 0.5 * (o0 + kFingerWidth);
  vs::FingerForceParams fp;
  fp.finger_stiffness_N_m = p.finger_stiffness_N_m;
  fp.tracker = p.tracker;
  vs::FingerForce force(fp);
  force.set_templates(frame, roi_between(left_tip, left_tip - 0.5 * kFingerWidth - kMargin),
                      roi_between(right_tip, right_tip + 0.5 * kFingerWidth + kMargin));
  // The unloaded pose: nothing between the fingers at these openings (they clear the part).
  for (double extra : {60e-6, 45e-6, 30e-6, 15e-6}) {
    if (extra != 60e-6) render_at(w + extra);
    force.add_unloaded(frame, w + extra);
  }
  force.fit_unloaded();
  r.unloaded_residual_px = force.unloaded_residual_px();

  // Closing onto the part (the tips stop at its faces), then the loaded frames at the command o.
  std::vector<double> ul, ur;
  for (int k = 0; k < p.loaded_frames; ++k) {
    render_at(microworld::grip_force_N(g, squeezed, w) > 0.0 ? w : o);
    const vs::FingerForceEstimate e = force.measure(frame, o);
    if (!e.found)
      throw ComputationFailed(fmt::format(
          "force by vision: a tip was lost in loaded frame {} (correlation {:.2f})", k, e.confidence));
    r.estimates_N.push_back(e.grip_force_N);
    ul.push_back(e.u_left_px);
    ur.push_back(e.u_right_px);
    if (k == 0) {
      imaging::Frame marked = frame;
      const auto mark = [&](double u) {
        const int cu = static_cast<int>(std::lround(u));
        for (int v = 0; v < marked.height; v += 2)
          if (cu >= 0 && cu < marked.width)
            marked.pixels[static_cast<std::size_t>(v) * marked.width + cu] = 0;
      };
      mark(e.u_left_px);
      mark(e.u_right_px);
      r.loaded_png = imaging::encode_png(marked);
    }
  }
  const auto mean_sd = [](const std::vector<double>& x, double& mean, double& sd) {
    mean = 0.0;
    for (double v : x) mean += v / static_cast<double>(x.size());
    double ss = 0.0;
    for (double v : x) ss += (v - mean) * (v - mean);
    sd = std::sqrt(ss / static_cast<double>(x.size() - 1));
  };
  double m = 0.0, sl = 0.0, sr = 0.0;
  mean_sd(r.estimates_N, r.mean_force_N, r.force_noise_N);
  mean_sd(ul, m, sl);
  mean_sd(ur, m, sr);
  // A tip moves 2 |b| px per metre of its own motion (b: px per metre of opening).
  const double tl = sl / (2.0 * std::abs(force.slope_left_px_m())),
               tr = sr / (2.0 * std::abs(force.slope_right_px_m()));
  r.tracking_noise_m = std::sqrt(0.5 * (tl * tl + tr * tr));
  return r;
}

}  // namespace mc::studies
