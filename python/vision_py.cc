// microcobot.vision: the microscope camera: render() a frame of a scene as an H x W
// numpy array (uint8 for 8-bit frames, else uint16), camera_model() the optics figures; and what
// the frames measure: TemplateTracker, Autofocus and sharpness() steppable from a
// Python loop on those arrays, fit_affine() for the pixel <-> stage calibration, VisualServo
// stepped frame by frame (a tracked feature in, the stage's velocity out). The same library
// calls as `microcobot vision ...` (vision/, platform/camera_scene).

#include <limits>
#include <optional>

#include "common.h"
#include "microcobot/imaging/renderer.h"
#include "microcobot/platform/camera_scene.h"
#include "microcobot/vision/affine_calibration.h"
#include "microcobot/vision/autofocus.h"
#include "microcobot/vision/sharpness.h"
#include "microcobot/vision/template_tracker.h"
#include "microcobot/vision/visual_servo.h"

namespace mc::py {
namespace {

using namespace pybind11::literals;

py::dict camera_model(const std::string& objective) {
  const imaging::ObjectiveParams o = imaging::objective_by_name(objective);
  const imaging::OpticsFigures f = imaging::optics_figures(o, imaging::SensorParams{});
  py::dict d;
  d["objective"] = o.name;
  d["magnification"] = f.magnification;
  d["numerical_aperture"] = f.numerical_aperture;
  d["wavelength_m"] = o.wavelength_m;
  d["working_distance_m"] = o.working_distance_m;
  d["resolution_m"] = f.resolution_m;
  d["dof_m"] = f.dof_m;
  d["dof_wave_m"] = f.dof_wave_m;
  d["dof_geometric_m"] = f.dof_geometric_m;
  d["um_per_px"] = f.um_per_px;
  d["field_of_view_x_m"] = f.field_of_view_x_m;
  d["field_of_view_y_m"] = f.field_of_view_y_m;
  d["psf_fwhm_m"] = f.psf_fwhm_m;
  d["airy_fwhm_m"] = f.airy_fwhm_m;
  return d;
}

py::array render(const std::string& scene, const std::string& objective, double focus_um,
                 std::optional<double> exposure_ms, std::optional<double> gain, int bit_depth,
                 const std::string& illumination, std::uint64_t seed, std::uint64_t frame,
                 std::optional<std::array<double, 3>> tool_um, double tool_yaw_deg, double part_yaw_deg) {
  const platform::PlatformConfig config = platform::scene_config(scene);
  imaging::CameraParams cam;
  cam.objective = imaging::objective_by_name(objective);
  cam.sensor.bit_depth = bit_depth;
  if (exposure_ms) cam.sensor.exposure_s = *exposure_ms * 1e-3;
  if (gain) cam.sensor.gain = *gain;
  cam.illumination.mode = illumination;
  platform::CameraScenePose pose = platform::initial_pose(config);
  if (tool_um)
    pose.tool_x_m = (*tool_um)[0] * 1e-6, pose.tool_y_m = (*tool_um)[1] * 1e-6,
    pose.tool_z_m = (*tool_um)[2] * 1e-6;
  if (!std::isfinite(tool_yaw_deg) || std::abs(tool_yaw_deg) > 360.0)
    throw InvalidInput("tool_yaw_deg: must be within [-360, 360], not " + std::to_string(tool_yaw_deg));
  if (!std::isfinite(part_yaw_deg) || std::abs(part_yaw_deg) > 360.0)
    throw InvalidInput("part_yaw_deg: must be within [-360, 360], not " + std::to_string(part_yaw_deg));
  pose.tool_yaw_rad = tool_yaw_deg * M_PI / 180.0;
  pose.part_yaw_rad = part_yaw_deg * M_PI / 180.0;
  cam.view_center_x_m = pose.part_x_m;
  cam.view_center_y_m = pose.part_y_m;
  if (!std::isfinite(focus_um)) throw InvalidInput("focus_um: must be finite");
  imaging::SceneSnapshot snapshot;
  platform::fill_camera_scene(config, pose, snapshot);
  imaging::Renderer renderer(cam);  // validates: ValueError naming the field
  imaging::CameraControls controls = renderer.default_controls();
  controls.focus_z_m = focus_um * 1e-6;
  imaging::Frame f;
  {
    py::gil_scoped_release release;
    renderer.render(snapshot, controls, seed, frame, f);
  }
  const std::vector<py::ssize_t> shape{f.height, f.width};
  if (f.bit_depth <= 8) {
    py::array_t<std::uint8_t> out(shape);
    auto* d = out.mutable_data();
    for (std::size_t i = 0; i < f.pixels.size(); ++i) d[i] = static_cast<std::uint8_t>(f.pixels[i]);
    return out;
  }
  py::array_t<std::uint16_t> out(shape);
  std::copy(f.pixels.begin(), f.pixels.end(), out.mutable_data());
  return out;
}

// A frame from a caller's 2-D uint8 or uint16 array (copied: the tracker keeps no reference).
imaging::Frame frame_of(const py::array& a) {
  const bool u8 = py::isinstance<py::array_t<std::uint8_t>>(a),
             u16 = py::isinstance<py::array_t<std::uint16_t>>(a);
  if (a.ndim() != 2 || (!u8 && !u16))
    throw InvalidInput("frame: a 2-D uint8 or uint16 array is needed (got " + std::to_string(a.ndim()) +
                       "-D of dtype " + std::string(py::str(a.dtype())) + ")");
  imaging::Frame f;
  f.height = static_cast<int>(a.shape(0));
  f.width = static_cast<int>(a.shape(1));
  f.bit_depth = u8 ? 8 : 16;
  f.pixels.resize(static_cast<std::size_t>(f.width) * static_cast<std::size_t>(f.height));
  if (u8) {
    const auto v = py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>::ensure(a);
    std::copy(v.data(), v.data() + f.pixels.size(), f.pixels.begin());
  } else {
    const auto v = py::array_t<std::uint16_t, py::array::c_style | py::array::forcecast>::ensure(a);
    std::copy(v.data(), v.data() + f.pixels.size(), f.pixels.begin());
  }
  return f;
}

imaging::PixelRoi roi_of(const std::optional<std::array<int, 4>>& roi, const imaging::Frame& f) {
  return roi ? imaging::PixelRoi{(*roi)[0], (*roi)[1], (*roi)[2], (*roi)[3]} : imaging::full_roi(f);
}

py::dict estimate_dict(const vision::TrackEstimate& e) {
  py::dict d;
  d["u_px"] = e.u_px;
  d["v_px"] = e.v_px;
  d["angle_rad"] = e.angle_rad;
  d["confidence"] = e.confidence;
  d["found"] = e.found;
  d["reacquired"] = e.reacquired;
  return d;
}

std::vector<Eigen::Vector2d> points_of(const py::array_t<double>& a, const char* name) {
  if (a.ndim() != 2 || a.shape(1) != 2)
    throw InvalidInput(std::string(name) + ": an N x 2 array is needed (got " + std::to_string(a.ndim()) +
                       "-D)");
  const auto v = a.unchecked<2>();
  std::vector<Eigen::Vector2d> p;
  for (py::ssize_t i = 0; i < v.shape(0); ++i) p.emplace_back(v(i, 0), v(i, 1));
  return p;
}

py::dict fit_affine_py(const py::array_t<double>& stage_m, const py::array_t<double>& pixel) {
  const vision::AffineFit fit = vision::fit_affine(points_of(stage_m, "stage_m"), points_of(pixel, "pixel"));
  const vision::AffineFigures f = vision::affine_figures(fit.map);
  py::array_t<double> a({2, 2}),
      residuals({static_cast<py::ssize_t>(fit.residuals_px.size()), py::ssize_t{2}});
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) a.mutable_at(i, j) = fit.map.A(i, j);
  for (std::size_t k = 0; k < fit.residuals_px.size(); ++k) {
    residuals.mutable_at(static_cast<py::ssize_t>(k), 0) = fit.residuals_px[k].x();
    residuals.mutable_at(static_cast<py::ssize_t>(k), 1) = fit.residuals_px[k].y();
  }
  py::dict d;
  d["A_px_per_m"] = a;
  d["b_px"] = py::make_tuple(fit.map.b.x(), fit.map.b.y());
  d["um_per_px_x"] = f.um_per_px_x;
  d["um_per_px_y"] = f.um_per_px_y;
  d["rotation_rad"] = f.rotation_rad;
  d["shear_rad"] = f.shear_rad;
  d["mirrored"] = f.mirrored;
  d["residual_rms_px"] = fit.residual_rms_px;
  d["residual_max_px"] = fit.residual_max_px;
  d["residuals_px"] = residuals;
  return d;
}

vision::Autofocus make_autofocus(const std::string& objective, double start_um,
                                 std::optional<std::array<double, 2>> range_um,
                                 std::optional<std::string> metric, bool reuse_coarse_samples) {
  if (!std::isfinite(start_um)) throw InvalidInput("start_um: must be finite");
  const imaging::OpticsFigures figures =
      imaging::optics_figures(imaging::objective_by_name(objective), imaging::SensorParams{});
  vision::AutofocusParams p =
      metric ? vision::autofocus_params_for(figures, start_um * 1e-6, vision::parse_focus_metric(*metric))
             : vision::autofocus_params_for(figures, start_um * 1e-6);
  if (range_um) {
    p.range_min_m = (*range_um)[0] * 1e-6;
    p.range_max_m = (*range_um)[1] * 1e-6;
  }
  p.reuse_coarse_samples = reuse_coarse_samples;
  return vision::Autofocus(p);  // validates: ValueError naming the field
}

vision::VisualServo make_servo(const py::array_t<double>& a_px_per_m, std::array<double, 2> b_px,
                               int width_px, int height_px, double gain_per_s, double max_speed_m_s,
                               double deadband_m, double converged_m, double max_feature_age_s) {
  if (a_px_per_m.ndim() != 2 || a_px_per_m.shape(0) != 2 || a_px_per_m.shape(1) != 2)
    throw InvalidInput("A_px_per_m: a 2 x 2 array is needed (got " + std::to_string(a_px_per_m.ndim()) +
                       "-D)");
  vision::AffineMap map;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) map.A(i, j) = a_px_per_m.at(i, j);
  map.b = {b_px[0], b_px[1]};
  vision::VisualServoParams p;
  p.gain_per_s = gain_per_s;
  p.max_speed_m_s = max_speed_m_s;
  p.deadband_m = deadband_m;
  p.converged_m = converged_m;
  p.max_feature_age_s = max_feature_age_s;
  return vision::VisualServo(p, map, width_px, height_px);  // validates: ValueError naming the field
}

py::dict servo_command_dict(const vision::ServoCommand& c) {
  py::dict d;
  d["velocity_m_s"] = py::make_tuple(c.velocity_m_s.x(), c.velocity_m_s.y());
  d["error_px"] = py::make_tuple(c.error_px.x(), c.error_px.y());
  d["error_m"] = py::make_tuple(c.error_m.x(), c.error_m.y());
  d["status"] = std::string(vision::to_string(c.status));
  return d;
}

}  // namespace

void bind_vision(py::module_& m) {
  m.def("camera_model", &camera_model, "objective"_a = "20x",
        "The optics figures of an objective on the default sensor (SI units): resolution_m (0.61 "
        "lambda/NA), dof_m (lambda n/NA^2 + n e/(M NA)), um_per_px, field_of_view_x_m/_y_m, psf_fwhm_m.");
  m.def(
      "render", &render, "scene"_a = "pick-place", "objective"_a = "20x", "focus_um"_a = 0.0,
      "exposure_ms"_a = py::none(), "gain"_a = py::none(), "bit_depth"_a = 12, "illumination"_a = "reflected",
      "seed"_a = 1, "frame"_a = 0, "tool_um"_a = py::none(), "tool_yaw_deg"_a = 0.0, "part_yaw_deg"_a = 0.0,
      "One camera frame of a scene (pick-place, pin-in-hole, optical-trap or a YAML file) seen from the top, "
      "centred on the part: an H x W array, uint8 for 8-bit frames, else uint16. Deterministic in (seed, "
      "frame). tool_yaw_deg turns the fingers about the tool point (the rotary axis), part_yaw_deg the "
      "part.");
  m.def(
      "sharpness",
      [](const py::array& frame, std::optional<std::array<int, 4>> roi, const std::string& metric) {
        const imaging::Frame f = frame_of(frame);
        return vision::sharpness(f, roi_of(roi, f), vision::parse_focus_metric(metric));
      },
      "frame"_a, "roi"_a = py::none(), "metric"_a = "normalized-variance",
      "A focus measure of the frame (a 2-D uint8/uint16 array) over roi = (x, y, width, height) (default: "
      "all): "
      "normalized-variance, tenengrad or brenner.");
  m.def(
      "fit_affine", &fit_affine_py, "stage_m"_a, "pixel"_a,
      "Least-squares pixel = A stage + b through N x 2 arrays of stage points [m] and tracked pixels: A, b, "
      "um_per_px_x/_y, rotation_rad, shear_rad, mirrored, residual_rms_px/_max_px, residuals_px.");
  py::class_<vision::TemplateTracker>(
      m, "TemplateTracker",
      "Sub-pixel template tracker (NCC coarse match, ECC refinement; vision/template_tracker.h). Frames are "
      "2-D "
      "uint8/uint16 arrays; positions in continuous pixel coordinates (a pixel's centre at its column, row).")
      .def(py::init([](int search_margin_px, double lost_below, double min_contrast_ratio, int ecc_blur_px,
                       double ecc_highpass_px, bool rotation) {
             vision::TrackerParams p;
             p.search_margin_px = search_margin_px;
             p.lost_below = lost_below;
             p.min_contrast_ratio = min_contrast_ratio;
             p.ecc_blur_px = ecc_blur_px;
             p.ecc_highpass_px = ecc_highpass_px;
             p.rotation = rotation;
             return vision::TemplateTracker(p);  // validates: ValueError naming the field
           }),
           "search_margin_px"_a = 24, "lost_below"_a = 0.5, "min_contrast_ratio"_a = 0.5, "ecc_blur_px"_a = 3,
           "ecc_highpass_px"_a = 0.0, "rotation"_a = false)
      .def(
          "set_template",
          [](vision::TemplateTracker& t, const py::array& frame, std::array<int, 4> roi) {
            t.set_template(frame_of(frame), imaging::PixelRoi{roi[0], roi[1], roi[2], roi[3]});
            return estimate_dict(t.last());
          },
          "frame"_a, "roi"_a, "Takes the template from roi = (x, y, width, height); returns its position.")
      .def(
          "track",
          [](vision::TemplateTracker& t, const py::array& frame) {
            const imaging::Frame f = frame_of(frame);
            py::gil_scoped_release release;
            return t.track(f);
          },
          "frame"_a, "Where the template is: u_px, v_px, angle_rad, confidence, found, reacquired.")
      .def(
          "track_near",
          [](vision::TemplateTracker& t, const py::array& frame, double u_px, double v_px) {
            const imaging::Frame f = frame_of(frame);
            py::gil_scoped_release release;
            return t.track_near(f, u_px, v_px);
          },
          "frame"_a, "u_px"_a, "v_px"_a, "The same, searched around a predicted position.");
  py::class_<vision::TrackEstimate>(m, "TrackEstimate", "One frame's estimate of a template tracker.")
      .def_readonly("u_px", &vision::TrackEstimate::u_px)
      .def_readonly("v_px", &vision::TrackEstimate::v_px)
      .def_readonly("angle_rad", &vision::TrackEstimate::angle_rad)
      .def_readonly("confidence", &vision::TrackEstimate::confidence)
      .def_readonly("found", &vision::TrackEstimate::found)
      .def_readonly("reacquired", &vision::TrackEstimate::reacquired);
  py::class_<vision::Autofocus>(m, "Autofocus",
                                "Steppable coarse-to-fine autofocus (vision/autofocus.h): set the focus to "
                                "next_focus_um, measure the frame with sharpness(frame, roi, next_metric), "
                                "observe() it, until done. reuse_coarse_samples=False when the coarse scan "
                                "(next_is_coarse) is measured on another region than the refinement.")
      .def(py::init(&make_autofocus), "objective"_a = "10x", "start_um"_a = 0.0, "range_um"_a = py::none(),
           "metric"_a = py::none(), "reuse_coarse_samples"_a = true)
      .def_property_readonly("done", &vision::Autofocus::done)
      .def_property_readonly("converged", &vision::Autofocus::converged)
      .def_property_readonly("next_focus_um",
                             [](const vision::Autofocus& a) { return a.next_focus_m() * 1e6; })
      .def_property_readonly(
          "next_metric",
          [](const vision::Autofocus& a) { return vision::focus_metric_name(a.next_metric()); })
      .def_property_readonly("next_is_coarse", &vision::Autofocus::next_is_coarse)
      .def_property_readonly("best_focus_um",
                             [](const vision::Autofocus& a) { return a.best_focus_m() * 1e6; })
      .def_property_readonly("frames_used", &vision::Autofocus::frames_used)
      .def_property_readonly("status", [](const vision::Autofocus& a) { return std::string(a.status()); })
      .def("observe", &vision::Autofocus::observe, "sharpness"_a,
           "The measure of the frame taken at next_focus_um with next_metric.");
  py::class_<vision::VisualServo>(
      m, "VisualServo",
      "Image-based visual servoing of the stage (vision/visual_servo.h, ViSP's vpServo law v = -lambda L+ e "
      "with L = A, the calibration's px/m): a feature's pixel in, the stage (x, y) velocity out, latency "
      "compensated from each frame's mid-exposure time; a lost or stale feature holds.")
      .def(py::init(&make_servo), "A_px_per_m"_a, "b_px"_a, "width_px"_a, "height_px"_a,
           "gain_per_s"_a = vision::VisualServoParams{}.gain_per_s,
           "max_speed_m_s"_a = vision::VisualServoParams{}.max_speed_m_s,
           "deadband_m"_a = vision::VisualServoParams{}.deadband_m,
           "converged_m"_a = vision::VisualServoParams{}.converged_m,
           "max_feature_age_s"_a = vision::VisualServoParams{}.max_feature_age_s)
      .def("set_target", &vision::VisualServo::set_target, "u_px"_a, "v_px"_a,
           "The pixel the feature is to reach (inside the frame); forgets the past commands.")
      .def_property_readonly("has_target", &vision::VisualServo::has_target)
      .def(
          "step",
          [](vision::VisualServo& s, double u_px, double v_px, bool found, double t_mid_exposure_s,
             double t_now_s, std::optional<double> hold_s) {
            if (!std::isfinite(t_mid_exposure_s) || !std::isfinite(t_now_s))
              throw InvalidInput("step: t_mid_exposure_s and t_now_s must be finite");
            if (hold_s && !(*hold_s >= 0.0)) throw InvalidInput("step: hold_s must be >= 0");
            const vision::ServoFeature f{u_px, v_px, found && std::isfinite(u_px) && std::isfinite(v_px),
                                         t_mid_exposure_s};
            return servo_command_dict(
                s.step(f, t_now_s, hold_s ? *hold_s : std::numeric_limits<double>::infinity()));
          },
          "u_px"_a, "v_px"_a, "found"_a, "t_mid_exposure_s"_a, "t_now_s"_a, "hold_s"_a = py::none(),
          "One frame: the feature where its frame (exposed at t_mid_exposure_s) saw it; the stage "
          "velocity to apply from t_now_s for hold_s (or until the next step): velocity_m_s, error_px, "
          "error_m (the error predicted for now), status (moving, converged, hold (target lost), hold "
          "(stale frame), no target).")
      .def("clear_history", &vision::VisualServo::clear_history,
           "Forgets the past commands (the stage was stopped by someone else).");
}

}  // namespace mc::py
