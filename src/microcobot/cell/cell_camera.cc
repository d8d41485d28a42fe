#include "microcobot/cell/cell_camera.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "microcobot/core/error.h"
#include "microcobot/imaging/renderer.h"
#include "microcobot/imaging/sensor_model.h"
#include "microcobot/platform/platform.h"
#include "microcobot/vision/depth_from_focus.h"
#include "microcobot/vision/sharpness.h"
#include "microcobot/vision/template_tracker.h"
#include "microcobot/vision/visual_servo.h"

namespace mc::cell {

namespace vs = mc::vision;

void CellCameraParams::validate() const {
  try {
    (void)imaging::objective_by_name(objective);
  } catch (const Error& e) {
    throw InvalidParams("objective", e.what());
  }
  require(width_px >= 0 && width_px <= 8192 && height_px >= 0 && height_px <= 8192, "width_px/height_px",
          "must be within [0, 8192] (0: the sensor's)");
  require(std::isfinite(look_s) && look_s >= 0.0 && look_s <= 5.0, "look_s", "must be within [0, 5] s",
          look_s);
  require(seed >= 0, "seed", "must be >= 0", seed);
  require(std::isfinite(min_confidence) && min_confidence > 0.0 && min_confidence < 1.0, "min_confidence",
          "must be within (0, 1)", min_confidence);
  require(std::isfinite(focus_step_dof) && focus_step_dof >= 0.5 && focus_step_dof <= 10.0, "focus_step_dof",
          "must be within [0.5, 10]", focus_step_dof);
  require(std::isfinite(band_inset_m) && band_inset_m >= 0.0 && band_inset_m <= 100e-6, "band_inset_m",
          "must be within [0, 100 um]", band_inset_m);
  require(std::isfinite(bore_search_m) && bore_search_m >= 1e-6 && bore_search_m <= 200e-6, "bore_search_m",
          "must be within [1, 200] um", bore_search_m);
  require(std::isfinite(view_error_m) && view_error_m >= 0.0 && view_error_m <= 50e-6, "view_error_m",
          "must be within [0, 50] um", view_error_m);
  require(std::isfinite(servo_converged_m) && servo_converged_m > 0.0 && servo_converged_m <= 10e-6,
          "servo_converged_m", "must be within (0, 10] um", servo_converged_m);
}

platform::CameraScenePose truth_pose(const platform::Platform& p) {
  const platform::PlatformConfig& c = p.config();
  platform::CameraScenePose pose;
  pose.tool_x_m = c.stage.home_x_m + p.axis(0).carried_position_m();
  pose.tool_y_m = c.stage.home_y_m + p.axis(1).carried_position_m();
  pose.tool_z_m = c.stage.home_z_m + p.axis(2).carried_position_m();
  pose.opening_m = p.gripper().opening_m();
  if (const auto* g = p.simulated_gripper()) {
    const auto& w = g->world_state();
    pose.tool_yaw_rad = g->yaw_rad();
    pose.part_x_m = w.part_m.x(), pose.part_y_m = w.part_m.y(), pose.part_z_m = w.part_m.z();
    pose.part_yaw_rad = w.part_yaw_rad;
    pose.deflection_x_m = w.finger_deflection_m.x(), pose.deflection_y_m = w.finger_deflection_m.y();
  }
  return pose;  // the stage holds while the cell looks: no motion blur
}

struct CellCamera::Impl {
  platform::PlatformConfig config;
  imaging::CameraParams camera;
  imaging::SensorModel sensor;
  imaging::SceneSnapshot scene;
  imaging::Frame frame, model;

  Impl(const CellCameraParams& p, const platform::PlatformConfig& c)
      : config(c), camera(make_camera(p)), sensor(camera.sensor) {}

  static imaging::CameraParams make_camera(const CellCameraParams& p) {
    imaging::CameraParams cam;
    cam.objective = imaging::objective_by_name(p.objective);
    if (p.width_px > 0) cam.sensor.width_px = p.width_px;
    if (p.height_px > 0) cam.sensor.height_px = p.height_px;
    return cam;
  }

  /// A renderer looking at `centre`.
  imaging::Renderer renderer_at(const Eigen::Vector2d& centre) const {
    imaging::CameraParams cam = camera;
    cam.view_center_x_m = centre.x();
    cam.view_center_y_m = centre.y();
    return imaging::Renderer(cam);
  }

  /// The frame of `pose` (noise from seed and index), or without the fingers and without noise
  /// (`expected`: what the cell expects, from what it is told).
  void render(imaging::Renderer& r, const platform::CameraScenePose& pose, double focus_z_m, bool expected,
              std::uint64_t seed, std::uint64_t index, imaging::Frame& out, bool plain_substrate = false) {
    platform::fill_camera_scene(config, pose, scene);
    if (expected) scene.fingers.clear();
    if (plain_substrate) scene.substrate.texture_contrast = 0.0;
    imaging::CameraControls controls = r.default_controls();
    controls.focus_z_m = focus_z_m;
    const std::vector<float>& photo_e = r.render_expected(scene, controls);
    sensor.read_out(photo_e, {controls.exposure_s, controls.gain}, seed, index, !expected, out);
  }
};

CellCamera::CellCamera(const CellCameraParams& params, const platform::PlatformConfig& config,
                       std::uint64_t stream)
    : p_(params),
      seed_(static_cast<std::uint64_t>(params.seed) * 1000003ULL + stream),
      view_rng_(seed_ ^ 0x7669657745727272ULL) {
  p_.validate();
  impl_ = std::make_unique<Impl>(p_, config);
}

CellCamera::~CellCamera() = default;

Eigen::Vector2d CellCamera::move_to_station(const Eigen::Vector2d& centre) {
  if (!at_station_ || (centre - station_).norm() > 1e-6) {
    station_ = centre;
    at_station_ = true;
    view_error_ = {view_rng_.normal(0.0, p_.view_error_m), view_rng_.normal(0.0, p_.view_error_m)};
  }
  return centre + view_error_;
}

namespace {

// The pin's pose with only the pin moved: what the model template is rendered from.
platform::CameraScenePose pin_at(platform::CameraScenePose pose, const Eigen::Vector2d& xy, double z_centre,
                                 double yaw) {
  pose.part_x_m = xy.x(), pose.part_y_m = xy.y(), pose.part_z_m = z_centre;
  pose.part_yaw_rad = yaw;
  return pose;
}

// The square's bounding box in pixels, `margin_px` wider each side, inside the frame (empty when it leaves
// it).
imaging::PixelRoi pin_roi(const imaging::Renderer& r, const Eigen::Vector2d& xy, double side_m, double yaw,
                          int margin_px) {
  const int width = r.camera().sensor.width_px, height = r.camera().sensor.height_px;
  const double half_m = 0.5 * side_m * (std::abs(std::cos(yaw)) + std::abs(std::sin(yaw)));
  const double half_px = half_m / r.camera().pixel_size_m() + margin_px;
  const int x0 = static_cast<int>(std::floor(r.u_of_x(xy.x()) - half_px));
  const int y0 = static_cast<int>(std::floor(r.v_of_y(xy.y()) - half_px));
  const int side = static_cast<int>(std::ceil(2.0 * half_px)) + 1;
  if (x0 < 0 || y0 < 0 || x0 + side > width || y0 + side > height) return {};
  return {x0, y0, side, side};
}

// The frame's value at continuous pixel (u, v), bilinear; NaN outside.
double bilinear(const imaging::Frame& f, double u, double v) {
  const double fu = std::floor(u), fv = std::floor(v);
  const int j = static_cast<int>(fu), i = static_cast<int>(fv);
  if (j < 0 || i < 0 || j + 1 >= f.width || i + 1 >= f.height) return std::nan("");
  const double a = u - fu, b = v - fv;
  const auto at = [&f](int row, int col) {
    return static_cast<double>(f.pixels[static_cast<std::size_t>(row) * static_cast<std::size_t>(f.width) +
                                        static_cast<std::size_t>(col)]);
  };
  return (1 - b) * ((1 - a) * at(i, j) + a * at(i, j + 1)) +
         b * ((1 - a) * at(i + 1, j) + a * at(i + 1, j + 1));
}

// The vertex of the parabola through (-1, ym), (0, y0), (1, yp): the sub-sample offset of an extremum.
double vertex_offset(double ym, double y0, double yp) {
  const double d = ym - 2.0 * y0 + yp;
  return d != 0.0 ? std::clamp(0.5 * (ym - yp) / d, -0.5, 0.5) : 0.0;
}

// The model template (`model` inside `roi`, centred on the expected pin at `expected_xy`, turned by
// `expected_yaw`) found in `frame` with the Euclidean warp: the pin's centre and yaw into `s` (its
// z left to the caller), or `miss` as the reason. The ROI is centred on the pin to within half a
// pixel, which the small turn moves by under 0.01 px: the pin's centre moves with the template's.
void match_model(const imaging::Renderer& r, const imaging::Frame& model, const imaging::Frame& frame,
                 const imaging::PixelRoi& roi, const Eigen::Vector2d& expected_xy, double expected_yaw,
                 double min_confidence, const char* miss, PinSighting& s, int search_margin_px = 0) {
  vs::TrackerParams tp;
  tp.rotation = true;
  if (search_margin_px > 0) tp.search_margin_px = search_margin_px;
  vs::TemplateTracker tracker(tp);
  tracker.set_template(model, roi);
  const double cu = roi.x + 0.5 * (roi.width - 1), cv = roi.y + 0.5 * (roi.height - 1);
  const vs::TrackEstimate e = tracker.track_near(frame, cu, cv);
  s.confidence = e.confidence;
  if (!e.found || e.confidence < min_confidence) {
    s.reason = miss;
    return;
  }
  const double px = r.camera().pixel_size_m();
  s.part_m.x() = expected_xy.x() + (e.u_px - cu) * px;
  s.part_m.y() = expected_xy.y() - (e.v_px - cv) * px;  // rows go down, y up
  s.yaw_rad = expected_yaw + e.angle_rad;
  s.found = true;
}

}  // namespace

PinSighting CellCamera::look_slot(const platform::CameraScenePose& truth, const PinModel& pin,
                                  const Eigen::Vector2d& nominal_xy, double nominal_yaw) {
  Impl& m = *impl_;
  imaging::Renderer r = m.renderer_at(nominal_xy);
  imaging::Renderer view = m.renderer_at(move_to_station(nominal_xy));
  const double focus = pin.height_m;  // the pin's top, standing on the tray
  m.render(view, truth, focus, false, seed_, static_cast<std::uint64_t>(frames_++), m.frame);
  m.render(r, pin_at(truth, nominal_xy, 0.5 * pin.height_m, nominal_yaw), focus, true, 0, 0, m.model);
  PinSighting s;
  s.yaw_rad = nominal_yaw;
  const imaging::PixelRoi roi = pin_roi(r, nominal_xy, pin.side_m, nominal_yaw, 12);
  if (roi.width == 0) {
    s.reason = "the pin's slot is not inside the camera's field";
    return s;
  }
  s.part_m.z() = 0.5 * pin.height_m;  // standing on the tray
  match_model(r, m.model, m.frame, roi, nominal_xy, nominal_yaw, p_.min_confidence,
              "the pin does not match its model in its slot", s);
  return s;
}

PinSighting CellCamera::look_bore(const platform::CameraScenePose& truth, const Eigen::Vector2d& drawn_xy,
                                  double yaw) {
  Impl& m = *impl_;
  imaging::Renderer r = m.renderer_at(drawn_xy);
  imaging::Renderer view = m.renderer_at(move_to_station(drawn_xy));
  constexpr double kRim = 0.0;  // the focus: the substrate's surface, the bore's rim
  m.render(view, truth, kRim, false, seed_, static_cast<std::uint64_t>(frames_++), m.frame);
  // The model: the bore where its drawing puts it, the pin and the fingers far from it.
  auto& world = m.config.world;
  const Eigen::Vector3d true_bore = world.target_m;
  world.target_m = {drawn_xy.x(), drawn_xy.y(), 0.0};
  // Its substrate plain: the texture is fixed to the plate, so round a bore that is not where it
  // is drawn the model's texture would be another one, and pull the match.
  m.render(r, pin_at(truth, drawn_xy + Eigen::Vector2d(10e-3, 10e-3), truth.part_z_m, truth.part_yaw_rad),
           kRim, true, 0, 0, m.model, /*plain_substrate=*/true);
  world.target_m = true_bore;
  PinSighting s;
  s.yaw_rad = yaw;
  if (world.hole_side_m <= 0.0) {
    s.reason = "a seat without a bore: nothing to see";
    return s;
  }
  const imaging::PixelRoi roi = pin_roi(r, drawn_xy, world.hole_side_m, yaw, 12);
  if (roi.width == 0) {
    s.reason = "the bore is not inside the camera's field";
    return s;
  }
  const int margin = static_cast<int>(std::ceil(p_.bore_search_m / r.camera().pixel_size_m()));
  match_model(r, m.model, m.frame, roi, drawn_xy, yaw, p_.min_confidence,
              "the bore does not match its drawing", s, margin);
  s.part_m.z() = 0.0;
  return s;
}

namespace {

// The pin's two faces across a profile: along `along` from `origin` (world, as the cell believes
// it: `r` maps it to the frame), sampled every half pixel over `reach` either side, each sample the
// mean across `across` from `across_from` to `across_to` (bilinear). The faces are the strongest
// gradient in each half (the near face rising into the bright top and the far one falling out of
// it, or the reverse), refined by a parabola; they must lie a side apart (within 3 pixels), each a
// clear edge (contrast >= 5 against the gradient's median). `centre`: their midpoint along `along`.
struct FacePair {
  bool found = false;
  double centre = 0.0, confidence = 0.0;
  const char* reason = "";
};
FacePair face_pair(const imaging::Frame& frame, const imaging::Renderer& r, const Eigen::Vector2d& origin,
                   const Eigen::Vector2d& along, const Eigen::Vector2d& across, double across_from,
                   double across_to, double reach, double side_m) {
  FacePair out;
  const double px = r.camera().pixel_size_m(), h = 0.5 * px;
  const int n = static_cast<int>(std::ceil(reach / h));
  std::vector<double> profile(static_cast<std::size_t>(2 * n + 1));
  for (int k = -n; k <= n; ++k) {
    double sum = 0.0;
    int count = 0;
    for (double c = across_from; c <= across_to + 1e-12; c += h) {
      const Eigen::Vector2d w = origin + c * across + k * h * along;
      const double value = bilinear(frame, r.u_of_x(w.x()), r.v_of_y(w.y()));
      if (std::isnan(value)) {
        out.reason = "the pin in the fingers leaves the camera's field";
        return out;
      }
      sum += value;
      ++count;
    }
    profile[static_cast<std::size_t>(k + n)] = sum / count;
  }
  std::vector<double> g(profile.size(), 0.0);
  for (std::size_t i = 1; i + 1 < profile.size(); ++i) g[i] = 0.5 * (profile[i + 1] - profile[i - 1]);
  const auto strongest = [&g](std::size_t from, std::size_t to) {
    std::size_t best = from;
    for (std::size_t i = from; i < to; ++i)
      if (std::abs(g[i]) > std::abs(g[best])) best = i;
    return best;
  };
  const std::size_t mid = static_cast<std::size_t>(n);
  const std::size_t a = strongest(2, mid), b = strongest(mid + 1, g.size() - 2);
  const auto edge = [&](std::size_t i) {
    return (static_cast<double>(i) - n +
            vertex_offset(std::abs(g[i - 1]), std::abs(g[i]), std::abs(g[i + 1]))) *
           h;
  };
  const double ea = edge(a), eb = edge(b);
  std::vector<double> mags(g.size());
  std::transform(g.begin(), g.end(), mags.begin(), [](double x) { return std::abs(x); });
  std::nth_element(mags.begin(), mags.begin() + static_cast<std::ptrdiff_t>(mags.size() / 2), mags.end());
  const double noise = std::max(mags[mags.size() / 2], 1e-9);
  out.confidence = std::min(std::abs(g[a]), std::abs(g[b])) / noise;
  if (std::abs((eb - ea) - side_m) > 3.0 * px || out.confidence < 5.0) {
    out.reason = "the pin's faces are not where a pin in the fingers has them";
    return out;
  }
  out.centre = 0.5 * (ea + eb);
  out.found = true;
  return out;
}

}  // namespace

PinSighting CellCamera::look_held(const platform::CameraScenePose& truth, const PinModel& pin,
                                  const Eigen::Vector3d& tool_m, double tool_yaw, double top_z_m) {
  Impl& m = *impl_;
  const imaging::Renderer r = m.renderer_at(tool_m.head<2>());
  imaging::Renderer view = m.renderer_at(move_to_station(tool_m.head<2>()));
  m.render(view, truth, top_z_m, false, seed_, static_cast<std::uint64_t>(frames_++), m.frame);
  PinSighting s;
  s.yaw_rad = tool_yaw;
  // The profile along the fingers' y over the pin and 30 um either side, across the band between
  // the fingers, |x_f| <= side / 2 - inset.
  const double half_band = 0.5 * pin.side_m - p_.band_inset_m;
  if (half_band < 2.0 * r.camera().pixel_size_m()) {
    s.reason = "the pin is too narrow for a band between the fingers";
    return s;
  }
  const Eigen::Vector2d ex(std::cos(tool_yaw), std::sin(tool_yaw)),
      ey(-std::sin(tool_yaw), std::cos(tool_yaw));
  const FacePair y = face_pair(m.frame, r, tool_m.head<2>(), ey, ex, -half_band, half_band,
                               0.5 * pin.side_m + 30e-6, pin.side_m);
  s.confidence = y.confidence;
  if (!y.found) {
    s.reason = y.reason;
    return s;
  }
  const Eigen::Vector2d xy = tool_m.head<2>() + y.centre * ey;
  s.part_m = {xy.x(), xy.y(), top_z_m - 0.5 * pin.height_m};
  s.found = true;
  return s;
}

PinSighting CellCamera::look_align(const platform::CameraScenePose& truth, const PinModel& pin,
                                   const Eigen::Vector2d& station_xy, const Eigen::Vector2d& bore_seen_xy,
                                   const Eigen::Vector3d& tool_m, double tool_yaw, double top_z_m) {
  Impl& m = *impl_;
  const imaging::Renderer r = m.renderer_at(station_xy);
  imaging::Renderer view = m.renderer_at(move_to_station(station_xy));
  m.render(view, truth, top_z_m, false, seed_, static_cast<std::uint64_t>(frames_++), m.frame);
  PinSighting s;
  s.yaw_rad = tool_yaw;
  const double px = r.camera().pixel_size_m();
  const double half_band = 0.5 * pin.side_m - p_.band_inset_m;
  if (half_band < 2.0 * px) {
    s.reason = "the pin is too narrow for a band between the fingers";
    return s;
  }
  const Eigen::Vector2d ex(std::cos(tool_yaw), std::sin(tool_yaw)),
      ey(-std::sin(tool_yaw), std::cos(tool_yaw));
  // Searched wider than the held look: the view's error moves everything it sees.
  const double reach = 0.5 * pin.side_m + 30e-6 + 3.0 * p_.view_error_m;
  // Along the fingers' y between them, as the held look.
  const FacePair y =
      face_pair(m.frame, r, tool_m.head<2>(), ey, ex, -half_band, half_band, reach, pin.side_m);
  if (!y.found) {
    s.confidence = y.confidence;
    s.reason = y.reason;
    return s;
  }
  // Along their x across the part of the pin below the fingers' ends (their bars begin half a
  // finger's width before the tool point and run along +y): both faces free there. 5 um clear of
  // the pin's corners and of the bars' dark outline (4 um), so that a 100 um pin keeps a band.
  constexpr double kClear = 5e-6;
  const double finger_w = m.config.world.gripper.finger_width_m;
  const double from = y.centre - 0.5 * pin.side_m + kClear;
  const double to = std::min(y.centre + 0.5 * pin.side_m - kClear, -0.5 * finger_w - kClear);
  if (to - from < 2.0 * px) {
    s.confidence = y.confidence;
    s.reason = "the fingers leave too little of the pin's faces along their x";
    return s;
  }
  const FacePair x = face_pair(m.frame, r, tool_m.head<2>(), ex, ey, from, to, reach, pin.side_m);
  s.confidence = std::min(x.confidence, y.confidence);
  if (!x.found) {
    s.reason = x.reason;
    return s;
  }
  const Eigen::Vector2d xy = tool_m.head<2>() + x.centre * ex + y.centre * ey;
  s.part_m = {xy.x(), xy.y(), top_z_m - 0.5 * pin.height_m};
  s.found = true;
  // The servo: the feature (the pin's pixel) against its target (the bore's, seen from this pose).
  vs::AffineMap map;  // the objective's nominal map, pixel = A world + b (rows down)
  map.A << 1.0 / px, 0.0, 0.0, -1.0 / px;
  map.b = Eigen::Vector2d(r.u_of_x(0.0), r.v_of_y(0.0));
  vs::VisualServoParams sp;
  sp.converged_m = p_.servo_converged_m;
  sp.deadband_m = std::min(sp.deadband_m, sp.converged_m);
  vs::VisualServo servo(sp, map, r.camera().sensor.width_px, r.camera().sensor.height_px);
  const Eigen::Vector2d target = map.pixel_of(bore_seen_xy), feature = map.pixel_of(xy);
  servo.set_target(target.x(), target.y());
  const vs::ServoCommand c = servo.step({feature.x(), feature.y(), true, 0.0}, 0.0);
  s.error_m = c.error_m;
  s.converged = c.status == vs::ServoStatus::kConverged;
  return s;
}

PinSighting CellCamera::look_placed(const platform::CameraScenePose& truth, const PinModel& pin,
                                    const Eigen::Vector2d& station_xy, const Eigen::Vector2d& bore_xy,
                                    double bore_yaw, double top_z_m) {
  Impl& m = *impl_;
  imaging::Renderer r = m.renderer_at(station_xy);
  imaging::Renderer view = m.renderer_at(move_to_station(station_xy));
  PinSighting s;
  s.yaw_rad = bore_yaw;
  const imaging::PixelRoi box = pin_roi(r, bore_xy, pin.side_m, bore_yaw, 12);
  if (box.width == 0) {
    s.reason = "the bore is not inside the camera's field";
    return s;
  }
  // Three frames: at the expected top and focus_step_dof depths of field either side; the
  // Tenengrad measure on the pin's box, the middle frame kept for the position.
  const double step = p_.focus_step_dof * r.figures().dof_m;
  std::array<vs::FocusSample, 3> samples;
  imaging::Frame focused;
  for (int k = 0; k < 3; ++k) {
    const double z = top_z_m + (k - 1) * step;
    m.render(view, truth, z, false, seed_, static_cast<std::uint64_t>(frames_++), m.frame);
    samples[static_cast<std::size_t>(k)] = {z, vs::tenengrad(m.frame, box)};
    if (k == 1) focused = m.frame;
  }
  const vs::FocusPeak peak = vs::focus_peak(samples);
  if (!peak.found) {
    s.reason = "no pin top in focus at the height of a pin down in its bore";
    return s;
  }
  m.render(r, pin_at(truth, bore_xy, top_z_m - 0.5 * pin.height_m, bore_yaw), top_z_m, true, 0, 0, m.model);
  s.part_m.z() = peak.z_m - 0.5 * pin.height_m;  // its centre below the top seen in focus
  match_model(r, m.model, focused, box, bore_xy, bore_yaw, p_.min_confidence,
              "the pin does not match its model in its bore", s);
  return s;
}

}  // namespace mc::cell
