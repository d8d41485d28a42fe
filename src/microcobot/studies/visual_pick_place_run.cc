#include "microcobot/studies/visual_pick_place_run.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/devices/encoderless_stage.h"
#include "microcobot/imaging/png_file.h"
#include "microcobot/imaging/renderer.h"
#include "microcobot/microworld/pick_place_world.h"
#include "microcobot/motion/step_map.h"
#include "microcobot/platform/camera_scene.h"

namespace mc::studies {

namespace vs = mc::vision;

const char* to_string(PickPlacePhase p) {
  switch (p) {
    case PickPlacePhase::kApproach:
      return "approach";
    case PickPlacePhase::kDescend:
      return "descend";
    case PickPlacePhase::kGrasp:
      return "grasp";
    case PickPlacePhase::kLift:
      return "lift";
    case PickPlacePhase::kTransport:
      return "transport";
    case PickPlacePhase::kLower:
      return "lower";
    case PickPlacePhase::kRelease:
      return "release";
    case PickPlacePhase::kRetract:
      return "retract";
    case PickPlacePhase::kDone:
      return "done";
  }
  return "?";
}

void VisualPickPlaceParams::validate() const {
  require(target_offset_m.allFinite() && target_offset_m.norm() <= 5e-3, "target_offset_m",
          "must be finite, within 5 mm", target_offset_m.norm());
  require(start_offset_m.allFinite() && start_offset_m.norm() <= 5e-3, "start_offset_m",
          "must be finite, within 5 mm", start_offset_m.norm());
  require(std::isfinite(hover_m) && hover_m > 0.0 && hover_m <= 1e-3, "hover_m", "must be within (0, 1 mm]",
          hover_m);
  require(std::isfinite(approach_opening_m) && approach_opening_m > 0.0, "approach_opening_m", "must be > 0",
          approach_opening_m);
  require(std::isfinite(grip_force_N) && grip_force_N > 0.0, "grip_force_N", "must be > 0", grip_force_N);
  require(std::isfinite(lift_m) && lift_m > 0.0 && lift_m <= 1e-3, "lift_m", "must be within (0, 1 mm]",
          lift_m);
  require(std::isfinite(press_m) && press_m >= 0.0 && press_m <= 100e-6, "press_m",
          "must be within [0, 100 um]", press_m);
  require(std::isfinite(retract_m) && retract_m >= 0.0 && retract_m <= 1e-3, "retract_m",
          "must be within [0, 1 mm]", retract_m);
  require(std::isfinite(z_speed_m_s) && z_speed_m_s > 0.0 && z_speed_m_s <= 10e-3, "z_speed_m_s",
          "must be within (0, 10 mm/s]", z_speed_m_s);
  require(gripper_frames >= 1 && gripper_frames <= 1000, "gripper_frames", "must be within [1, 1000]",
          gripper_frames);
  require(settle_frames >= 1 && settle_frames <= 100, "settle_frames", "must be within [1, 100]",
          settle_frames);
  require(phase_frames >= settle_frames && phase_frames <= 10000, "phase_frames",
          "must be within [settle_frames, 10000]", phase_frames);
  require(std::isfinite(calibration_scale_error) && std::abs(calibration_scale_error) < 0.5,
          "calibration_scale_error", "must be within (-0.5, 0.5)", calibration_scale_error);
  require(std::isfinite(processing_latency_s) && processing_latency_s >= 0.0 && processing_latency_s < 1.0,
          "processing_latency_s", "must be within [0, 1) s", processing_latency_s);
  require(template_px >= 8 && template_px <= 1024, "template_px", "must be within [8, 1024]", template_px);
  require(width_px >= 0 && height_px >= 0, "width_px/height_px", "must be >= 0 (0: the sensor's)");
  servo.validate();
  tracker.validate();
}

namespace {

std::string marked_png(const imaging::Frame& frame, const Eigen::Vector2d& feature,
                       const Eigen::Vector2d& target) {
  return imaging::encode_marked_png(frame, feature.x(), feature.y(), target.x(), target.y());
}

// A square ROI of `side` pixels centred on (u, v); InvalidInput naming `what` when it leaves the frame.
imaging::PixelRoi centred_roi(double u, double v, int side, const imaging::Frame& f, const char* what) {
  const imaging::PixelRoi roi{static_cast<int>(std::lround(u - 0.5 * (side - 1))),
                              static_cast<int>(std::lround(v - 0.5 * (side - 1))), side, side};
  if (roi.x < 0 || roi.y < 0 || roi.x + side > f.width || roi.y + side > f.height)
    throw InvalidInput(
        fmt::format("{} at ({:.0f}, {:.0f}) px: its {} px template is not inside the {}x{} frame", what, u, v,
                    side, f.width, f.height));
  return roi;
}

}  // namespace

VisualPickPlaceResult run_visual_pick_place(const VisualPickPlaceParams& p) {
  p.validate();
  platform::PlatformConfig config = platform::scene_config(p.scene);
  if (config.optical_trap_scene())
    throw InvalidInput("--scene " + p.scene + ": a pick-and-place needs a part (not the optical trap)");
  auto& w = config.world;
  if (w.hole_side_m > 0.0)
    throw InvalidInput("--scene " + p.scene +
                       ": a part with a hole at its target is an insertion, not a placement");
  const Eigen::Vector2d part0 = w.part_start_m.head<2>();
  const Eigen::Vector2d target = part0 + p.target_offset_m;
  w.target_m.head<2>() = target;
  require(p.approach_opening_m > w.part_side_m && p.approach_opening_m <= w.gripper.max_opening_m,
          "approach_opening_m", "must be wider than the part and within the gripper's opening",
          p.approach_opening_m);
  const double grip_opening = w.part_side_m - p.grip_force_N / w.gripper.finger_stiffness_N_m;
  require(grip_opening >= w.gripper.min_opening_m, "grip_force_N", "more than the closed gripper squeezes",
          p.grip_force_N);
  const microworld::PickPlaceWorld world(w);
  microworld::PickPlaceState ws = world.initial_state();

  imaging::CameraParams cam;
  cam.objective = imaging::objective_by_name(p.objective);
  if (p.width_px > 0) cam.sensor.width_px = p.width_px;
  if (p.height_px > 0) cam.sensor.height_px = p.height_px;
  cam.view_center_x_m = 0.5 * (part0.x() + target.x());  // the part and its target in one field
  cam.view_center_y_m = 0.5 * (part0.y() + target.y());
  imaging::Renderer renderer(cam);
  const double pixel_m = cam.pixel_size_m();
  const double part_top = w.height_m();
  imaging::CameraControls controls = renderer.default_controls();
  controls.focus_z_m = part_top + p.hover_m;  // the tips while approaching, the part's top lifted
  const double T = 1.0 / cam.sensor.frame_rate_Hz, exposure = controls.exposure_s;

  // XY: the encoderless stage. Z: the stage's Z axis under its own position controller (its
  // sensor), a follower of the commanded height at `z_speed_m_s` (header: why not open loop).
  const stickslip::ActuatorModel model(platform::axis_params(config));
  const motion::StepMap map(model, config.stage.step_map);
  const Eigen::Vector2d home(config.stage.home_x_m, config.stage.home_y_m);
  const Eigen::Vector3d tool0(part0.x() + p.start_offset_m.x(), part0.y() + p.start_offset_m.y(),
                              part_top + p.hover_m);
  devices::EncoderlessStage xy(model, map, {}, tool0.head<2>() - home);
  double z = tool0.z(), z_goal = tool0.z();
  auto z_moving = [&] { return z != z_goal; };
  const double tick = xy.tick_s();
  auto tool = [&] {
    const Eigen::Vector2d s = home + xy.true_position_m();
    return Eigen::Vector3d(s.x(), s.y(), z);
  };
  double opening_cmd = p.approach_opening_m;
  ws.gripper.free_opening_m = p.approach_opening_m;
  ws.last_gripper_m = tool0;
  microworld::PickPlaceOutput out = world.step(ws, tool0, opening_cmd, tick);
  // The world follows the stage tick by tick (its contacts switch on the tips' motion).
  auto advance_to = [&](double t) {
    while (xy.time_s() + 0.5 * tick < t) {
      xy.advance(tick);
      const double dz = std::clamp(z_goal - z, -p.z_speed_m_s * tick, p.z_speed_m_s * tick);
      z = std::abs(z_goal - z) <= p.z_speed_m_s * tick ? z_goal : z + dz;
      out = world.step(ws, tool(), opening_cmd, tick);
    }
    if (xy.diverged()) throw ComputationFailed("visual pick-and-place: the stick-slip model diverged");
  };

  vs::AffineMap believed;
  believed.A << (1.0 + p.calibration_scale_error) / pixel_m, 0.0, 0.0,
      -(1.0 - p.calibration_scale_error) / pixel_m;
  vs::VisualServo servo(p.servo, believed, cam.sensor.width_px, cam.sensor.height_px);
  vs::TemplateTracker tips(p.tracker), part_tracker(p.tracker), held(p.tracker);
  const int part_px = static_cast<int>(std::lround(w.part_side_m / pixel_m)) + 16;
  require(part_px <= 1024, "objective", "makes the part's template over 1024 px", part_px);

  VisualPickPlaceResult r;
  r.pixel_m = pixel_m;
  imaging::Frame frame;
  imaging::SceneSnapshot scene;
  PickPlacePhase phase = PickPlacePhase::kApproach;
  int phase_start = 0, converged_count = 0;
  Eigen::Vector2d tip_offset_px = Eigen::Vector2d::Zero();   // tips' template centre - tool point
  Eigen::Vector2d part_offset_px = Eigen::Vector2d::Zero();  // part's template centre - part centre
  Eigen::Vector2d held_offset_px = Eigen::Vector2d::Zero();  // held template centre - part centre
  Eigen::Vector2d tool_px = Eigen::Vector2d::Zero(), part_px_seen = Eigen::Vector2d::Zero();
  Eigen::Vector2d last_px = Eigen::Vector2d::Zero(), v_prev = Eigen::Vector2d::Zero();
  double hold_prev = 0.0;
  const Eigen::Vector2d target_px(renderer.u_of_x(target.x()), renderer.v_of_y(target.y()));  // a click
  const double z_travel = 2.0 * (p.hover_m + 0.5 * w.height_m() + p.lift_m + p.press_m) + p.retract_m;
  const int max_frames = 2 * p.phase_frames + static_cast<int>(std::ceil(z_travel / p.z_speed_m_s / T)) +
                         4 * p.gripper_frames + 8;
  auto begin = [&](PickPlacePhase next, int k) {
    phase = next;
    phase_start = k;
    converged_count = 0;
  };

  for (int k = 0; k < max_frames && phase != PickPlacePhase::kDone; ++k) {
    const double t0 = k * T;
    advance_to(t0);
    const Eigen::Vector3d x_start = tool();
    advance_to(t0 + 0.5 * exposure);
    const Eigen::Vector3d x_mid = tool();
    const Eigen::Vector3d part_mid = ws.part_m;
    advance_to(t0 + exposure);
    const Eigen::Vector3d v_blur = (tool() - x_start) / exposure;
    platform::CameraScenePose pose;
    pose.tool_x_m = x_mid.x(), pose.tool_y_m = x_mid.y(), pose.tool_z_m = x_mid.z();
    pose.opening_m = out.opening_m;
    pose.part_x_m = part_mid.x(), pose.part_y_m = part_mid.y(), pose.part_z_m = part_mid.z();
    pose.vx_m_s = v_blur.x(), pose.vy_m_s = v_blur.y();
    if (ws.phase != microworld::PartPhase::kOnSubstrate)
      pose.part_vx_m_s = v_blur.x(), pose.part_vy_m_s = v_blur.y();
    platform::fill_camera_scene(config, pose, scene);
    renderer.render(scene, controls, p.seed, static_cast<std::uint64_t>(k), frame);
    const double t_mid = xy.time_s() - 0.5 * exposure;

    PickPlaceFrame rec;
    rec.phase = phase;
    rec.t_mid_s = t_mid;
    rec.tool_m = x_mid;
    rec.part_m = part_mid;
    rec.grip_force_N = out.grip_force_N;
    vs::ServoFeature feature;
    feature.t_mid_exposure_s = t_mid;
    vs::TemplateTracker* servoed = nullptr;
    if (k == 0) {
      // The operator's clicks: the tool point (the template on a finger's tip, carrying the
      // offset to it) and the part's centre (a template on the part). The finger on the field's
      // side of the part: over the part, the other one may be outside the field.
      const Eigen::Vector2d g0(renderer.u_of_x(x_mid.x()), renderer.v_of_y(x_mid.y()));
      const double side = renderer.u_of_x(part0.x()) < 0.5 * (frame.width - 1) ? 1.0 : -1.0;
      const double tip_u = renderer.u_of_x(x_mid.x() + side * 0.5 * (p.approach_opening_m + 40e-6));
      tips.set_template(frame,
                        centred_roi(tip_u, g0.y() - 0.25 * p.template_px, p.template_px, frame, "the tips"));
      tip_offset_px = Eigen::Vector2d(tips.last().u_px, tips.last().v_px) - g0;
      const Eigen::Vector2d c0(renderer.u_of_x(part0.x()), renderer.v_of_y(part0.y()));
      part_tracker.set_template(frame, centred_roi(c0.x(), c0.y(), part_px, frame, "the part"));
      part_offset_px = Eigen::Vector2d(part_tracker.last().u_px, part_tracker.last().v_px) - c0;
      servo.set_target(c0.x() + tip_offset_px.x(), c0.y() + tip_offset_px.y());
      if (target_px.x() < 0.0 || target_px.y() < 0.0 || target_px.x() > frame.width - 1 ||
          target_px.y() > frame.height - 1)
        throw InvalidInput(fmt::format("the target ({:.0f}, {:.0f}) px is not inside the {}x{} frame",
                                       target_px.x(), target_px.y(), frame.width, frame.height));
      feature.u_px = tips.last().u_px, feature.v_px = tips.last().v_px, feature.found = true;
      rec.confidence = 1.0;
      r.first_png = marked_png(frame, {feature.u_px, feature.v_px}, servo.target_px());
    } else if (phase == PickPlacePhase::kApproach) {
      servoed = &tips;
    } else if (phase == PickPlacePhase::kTransport && k > phase_start) {
      servoed = &held;
    } else if (phase == PickPlacePhase::kTransport) {
      // The part lifted and at rest: a template on it (part and fingers move as one), its centre
      // where the grasp put it: the tool point's column, the part's row before the grasp.
      const Eigen::Vector2d centre(tool_px.x(), part_px_seen.y());
      held.set_template(frame, centred_roi(centre.x(), centre.y(), part_px, frame, "the held part"));
      held_offset_px = Eigen::Vector2d(held.last().u_px, held.last().v_px) - centre;
      servo.set_target(target_px.x() + held_offset_px.x(), target_px.y() + held_offset_px.y());
      feature.u_px = held.last().u_px, feature.v_px = held.last().v_px, feature.found = true;
      rec.confidence = 1.0;
      r.grasp_png = marked_png(frame, {feature.u_px, feature.v_px}, servo.target_px());
    }
    if (servoed) {
      // Searched where the commanded motion since the last frame puts it (no encoder).
      const Eigen::Vector2d predicted = last_px + believed.A * (v_prev * hold_prev);
      const vs::TrackEstimate e = servoed->track_near(frame, predicted.x(), predicted.y());
      feature.u_px = e.u_px, feature.v_px = e.v_px, feature.found = e.found;
      rec.confidence = e.confidence;
    }
    if (feature.found) last_px = Eigen::Vector2d(feature.u_px, feature.v_px);
    rec.u_px = feature.u_px, rec.v_px = feature.v_px, rec.found = feature.found;

    advance_to(t0 + exposure + p.processing_latency_s);
    const double t_now = xy.time_s();
    const double hold = (k + 1) * T - t_now - tick;  // every run ends before the next exposure
    Eigen::Vector2d v_cmd = Eigen::Vector2d::Zero();
    const int in_phase = k - phase_start;
    switch (phase) {
      case PickPlacePhase::kApproach:
      case PickPlacePhase::kTransport: {
        const vs::ServoCommand c = servo.step(feature, t_now, hold);
        rec.status = c.status;
        rec.servo_error_m = c.error_m;
        converged_count = c.status == vs::ServoStatus::kConverged ? converged_count + 1 : 0;
        if (converged_count >= p.settle_frames) {
          // Converged on frames of a stage at rest (each run ends before the next exposure): it
          // stays where this frame saw it.
          if (phase == PickPlacePhase::kApproach) {
            r.approach_frames = k + 1;
            tool_px = Eigen::Vector2d(feature.u_px, feature.v_px) - tip_offset_px;
            const vs::TrackEstimate e =
                part_tracker.track_near(frame, part_tracker.last().u_px, part_tracker.last().v_px);
            if (!e.found) {
              r.failed_phase = phase;
              break;
            }
            part_px_seen = Eigen::Vector2d(e.u_px, e.v_px) - part_offset_px;
            z_goal = tool0.z() - (p.hover_m + 0.5 * w.height_m());
            begin(PickPlacePhase::kDescend, k);
          } else {
            r.transport_frames = k + 1 - phase_start;
            z_goal -= p.lift_m + p.press_m;
            begin(PickPlacePhase::kLower, k);
          }
        } else if (in_phase >= p.phase_frames) {
          r.failed_phase = phase;
        } else {
          v_cmd = c.velocity_m_s;
        }
        break;
      }
      case PickPlacePhase::kDescend:
        if (!z_moving()) {
          r.grasp_error_m = (x_mid - ws.part_m).head<2>();
          opening_cmd = grip_opening;
          begin(PickPlacePhase::kGrasp, k);
        }
        break;
      case PickPlacePhase::kGrasp:
        if (in_phase >= p.gripper_frames) {
          z_goal += p.lift_m;
          begin(PickPlacePhase::kLift, k);
        }
        break;
      case PickPlacePhase::kLift:
        if (!z_moving()) begin(PickPlacePhase::kTransport, k + 1);
        break;
      case PickPlacePhase::kLower:
        if (!z_moving()) {
          opening_cmd = p.approach_opening_m;
          begin(PickPlacePhase::kRelease, k);
        }
        break;
      case PickPlacePhase::kRelease:
        if (in_phase >= p.gripper_frames) {
          z_goal += p.retract_m;
          begin(PickPlacePhase::kRetract, k);
        }
        break;
      case PickPlacePhase::kRetract:
        if (!z_moving()) begin(PickPlacePhase::kDone, k);
        break;
      case PickPlacePhase::kDone:
        break;
    }
    xy.command(v_cmd, hold);  // zero: the axes hold
    v_prev = v_cmd;
    hold_prev = hold;
    rec.velocity_m_s = v_cmd;
    r.frames.push_back(rec);
    if (r.failed_phase != PickPlacePhase::kDone) break;
    if (phase == PickPlacePhase::kDone || k == max_frames - 1)
      r.last_png = marked_png(frame, target_px, target_px);
  }
  // Whatever happened, the sequence ends holding: the runs stop, the gripper keeps its command.
  if (phase != PickPlacePhase::kDone) {
    xy.halt();
    z_goal = z;
    if (r.failed_phase == PickPlacePhase::kDone) r.failed_phase = phase;
  }
  r.completed = phase == PickPlacePhase::kDone;
  const double t_end = xy.time_s();
  advance_to(t_end + T);
  while ((xy.moving() || z_moving()) && xy.time_s() < t_end + 2.0) advance_to(xy.time_s() + T);
  r.duration_s = xy.time_s();
  r.xy_holding = !xy.moving() && xy.true_velocity_m_s().norm() < 1e-6;
  r.z_holding = !z_moving();
  r.gripper_holding = std::abs(ws.gripper.free_opening_m - std::clamp(opening_cmd, w.gripper.min_opening_m,
                                                                      w.gripper.max_opening_m)) < 1e-9;
  r.part_on_substrate = ws.phase == microworld::PartPhase::kOnSubstrate;
  r.placement_error_m = ws.part_m.head<2>() - target;
  if (r.last_png.empty()) r.last_png = marked_png(frame, target_px, target_px);
  return r;
}

}  // namespace mc::studies
