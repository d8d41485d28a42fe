#include "microcobot/studies/visual_servo_run.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/devices/encoderless_stage.h"
#include "microcobot/imaging/png_file.h"
#include "microcobot/imaging/renderer.h"
#include "microcobot/motion/step_map.h"
#include "microcobot/platform/camera_scene.h"

namespace mc::studies {

namespace vs = mc::vision;

void ServoRunParams::validate() const {
  require(max_frames >= 1 && max_frames <= 100000, "max_frames", "must be within [1, 100000]", max_frames);
  require(start_offset_m.allFinite() && start_offset_m.norm() <= 5e-3, "start_offset_m",
          "must be finite, within 5 mm", start_offset_m.norm());
  require(std::isfinite(calibration_scale_error) && std::abs(calibration_scale_error) < 0.5,
          "calibration_scale_error", "must be within (-0.5, 0.5)", calibration_scale_error);
  require(std::isfinite(hover_m) && hover_m >= 0.0 && hover_m <= 1e-3, "hover_m", "must be within [0, 1 mm]",
          hover_m);
  require(std::isfinite(processing_latency_s) && processing_latency_s >= 0.0 && processing_latency_s < 1.0,
          "processing_latency_s", "must be within [0, 1) s", processing_latency_s);
  require(template_px >= 8 && template_px <= 1024, "template_px", "must be within [8, 1024]", template_px);
  require(width_px >= 0 && height_px >= 0, "width_px/height_px", "must be >= 0 (0: the sensor's)");
  servo.validate();
  tracker.validate();
}

ServoRunResult run_visual_servo(const ServoRunParams& p) {
  p.validate();
  const platform::PlatformConfig config = platform::scene_config(p.scene);
  if (config.optical_trap_scene())
    throw InvalidInput("--scene " + p.scene + ": the visual servo brings the gripper over a part");
  imaging::CameraParams cam;
  cam.objective = imaging::objective_by_name(p.objective);
  if (p.width_px > 0) cam.sensor.width_px = p.width_px;
  if (p.height_px > 0) cam.sensor.height_px = p.height_px;
  platform::CameraScenePose pose = platform::initial_pose(config);
  // The goal: the tool point over the part's centre. The view is centred on it.
  const Eigen::Vector2d goal(pose.part_x_m, pose.part_y_m);
  cam.view_center_x_m = goal.x();
  cam.view_center_y_m = goal.y();
  imaging::Renderer renderer(cam);
  const double pixel_m = cam.pixel_size_m();
  imaging::SceneSnapshot scene;
  platform::fill_camera_scene(config, pose, scene);
  const double part_top = scene.parts.front().z_top_m;
  pose.tool_z_m = part_top + p.hover_m;
  pose.opening_m = 20e-6;  // the tips 20 um apart: their gap is part of the template
  imaging::CameraControls controls = renderer.default_controls();
  controls.focus_z_m = pose.tool_z_m;  // the tips in focus
  const double T = 1.0 / cam.sensor.frame_rate_Hz, exposure = controls.exposure_s;

  // The stage (its axes along the camera's x and y), its sliders' origin at the stage's home.
  const stickslip::ActuatorModel model(platform::axis_params(config));
  const motion::StepMap map(model, config.stage.step_map);
  const Eigen::Vector2d home(config.stage.home_x_m, config.stage.home_y_m);
  devices::EncoderlessStage stage(model, map, {}, goal + p.start_offset_m - home);

  // The servo's calibration: pixel = A stage + b, A = diag(1, -1) / pixel (rows go down), with
  // its scale error (b does not enter the law).
  vs::AffineMap believed;
  believed.A << (1.0 + p.calibration_scale_error) / pixel_m, 0.0, 0.0,
      -(1.0 - p.calibration_scale_error) / pixel_m;
  vs::VisualServo servo(p.servo, believed, cam.sensor.width_px, cam.sensor.height_px);
  vs::TemplateTracker tracker(p.tracker);

  ServoRunResult r;
  r.pixel_m = pixel_m;
  r.converged_m = p.servo.converged_m;
  imaging::Frame frame;
  Eigen::Vector2d last_px = Eigen::Vector2d::Zero();
  Eigen::Vector2d template_offset_px = Eigen::Vector2d::Zero();
  // The commands since the last frame's mid-exposure (the tracker's prediction: commanded motion).
  Eigen::Vector2d v_prev = Eigen::Vector2d::Zero();
  double hold_prev = 0.0;
  for (int k = 0; k < p.max_frames; ++k) {
    const double t0 = k * T;
    stage.advance(t0 - stage.time_s());
    const Eigen::Vector2d x_start = stage.true_position_m();
    stage.advance(t0 + 0.5 * exposure - stage.time_s());
    const Eigen::Vector2d x_mid = stage.true_position_m();
    stage.advance(t0 + exposure - stage.time_s());
    const Eigen::Vector2d x_end = stage.true_position_m();
    if (stage.diverged()) throw ComputationFailed("visual servo: the stick-slip model diverged");
    const double t_mid = stage.time_s() - 0.5 * exposure;
    const Eigen::Vector2d tool = home + x_mid, v_blur = (x_end - x_start) / exposure;
    pose.tool_x_m = tool.x();
    pose.tool_y_m = tool.y();
    pose.vx_m_s = v_blur.x();
    pose.vy_m_s = v_blur.y();
    platform::fill_camera_scene(config, pose, scene);
    if (k >= p.occlude_from && k < p.occlude_to) scene.fingers.clear();
    renderer.render(scene, controls, p.seed, static_cast<std::uint64_t>(k), frame);

    ServoFrame rec;
    rec.t_mid_s = t_mid;
    rec.true_error_m = tool - goal;
    vs::ServoFeature feature;
    feature.t_mid_exposure_s = t_mid;
    if (k == 0) {
      // The operator's clicks: the template on the tips (and the gap between them), the target on
      // the part's centre, the tool point's offset in the template carried over to it.
      const double u = renderer.u_of_x(tool.x()), v = renderer.v_of_y(tool.y()) - 0.25 * p.template_px;
      const imaging::PixelRoi roi{static_cast<int>(std::lround(u - 0.5 * (p.template_px - 1))),
                                  static_cast<int>(std::lround(v - 0.5 * (p.template_px - 1))), p.template_px,
                                  p.template_px};
      tracker.set_template(frame, roi);
      template_offset_px = Eigen::Vector2d(tracker.last().u_px - renderer.u_of_x(tool.x()),
                                           tracker.last().v_px - renderer.v_of_y(tool.y()));
      r.target_px =
          Eigen::Vector2d(renderer.u_of_x(goal.x()), renderer.v_of_y(goal.y())) + template_offset_px;
      servo.set_target(r.target_px.x(), r.target_px.y());
      feature.u_px = tracker.last().u_px;
      feature.v_px = tracker.last().v_px;
      feature.found = true;
      rec.confidence = 1.0;
    } else {
      // Searched where the commanded motion since the last frame puts it (no encoder).
      const Eigen::Vector2d moved = v_prev * hold_prev;
      const Eigen::Vector2d predicted = last_px + believed.A * moved;
      const vs::TrackEstimate e = tracker.track_near(frame, predicted.x(), predicted.y());
      feature.u_px = e.u_px;
      feature.v_px = e.v_px;
      feature.found = e.found;
      rec.confidence = e.confidence;
    }
    if (feature.found) {
      last_px = Eigen::Vector2d(feature.u_px, feature.v_px);
    }
    rec.u_px = feature.u_px;
    rec.v_px = feature.v_px;
    rec.found = feature.found;
    if (k == 0) {
      r.first_png =
          imaging::encode_marked_png(frame, feature.u_px, feature.v_px, r.target_px.x(), r.target_px.y());
    }

    // The command, from the frame's end plus the processing latency.
    stage.advance(t0 + exposure + p.processing_latency_s - stage.time_s());
    const double t_now = stage.time_s();
    // The run completes before the next exposure: the frame sees the stage at rest.
    const double hold = (k + 1) * T - t_now - stage.tick_s();
    const vs::ServoCommand c = servo.step(feature, t_now, hold);
    stage.command(c.velocity_m_s, hold);
    v_prev = c.velocity_m_s;
    hold_prev = hold;
    rec.servo_error_m = c.error_m;
    rec.velocity_m_s = c.velocity_m_s;
    rec.status = c.status;
    rec.periods_x = stage.last_periods(0);
    rec.periods_y = stage.last_periods(1);
    r.frames.push_back(rec);
    if (k == p.max_frames - 1) {
      r.last_png =
          imaging::encode_marked_png(frame, feature.u_px, feature.v_px, r.target_px.x(), r.target_px.y());
    }
  }
  // The last command's run completes; the stage at rest is judged.
  stage.advance(p.max_frames * T + T - stage.time_s());
  while (stage.moving() && stage.time_s() < p.max_frames * T + 2.0) stage.advance(T);
  if (stage.diverged()) throw ComputationFailed("visual servo: the stick-slip model diverged");
  r.final_error_m = home + stage.true_position_m() - goal;
  for (int k = static_cast<int>(r.frames.size()) - 1; k >= 0; --k) {
    if (r.frames[static_cast<std::size_t>(k)].true_error_m.norm() > p.servo.converged_m) break;
    r.converged_frame = k;
  }
  if (r.final_error_m.norm() > p.servo.converged_m) r.converged_frame = -1;
  return r;
}

}  // namespace mc::studies
