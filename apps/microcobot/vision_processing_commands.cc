// `microcobot vision calibrate|track`: the camera's frames turned into measurements.
// `calibrate` moves the tool through a grid and fits the pixel <-> stage affine map; `track`
// follows a part or the tool along a path (`autofocus`: vision_autofocus_command.cc). Each is
// judged against the simulation's truth.

#include "vision_processing_commands.h"
#include "vision_camera_options.h"

#include <cmath>
#include <filesystem>
#include <optional>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/imaging/png_file.h"
#include "microcobot/imaging/renderer.h"
#include "microcobot/platform/camera_scene.h"
#include "microcobot/vision/affine_calibration.h"
#include "microcobot/vision/template_tracker.h"

namespace mc::cli {
namespace {

namespace vs = mc::vision;
namespace pf = mc::platform;

// The stage's axes as mounted under the microscope (the calibration's ground truth): x along
// (cos a, sin a) scaled by scale_x, y along (-sin(a + skew), cos(a + skew)) scaled by scale_y, in
// the camera's (y-up) object plane.
struct StageGeometry {
  double angle_deg = 0.0, skew_deg = 0.0, scale_x = 1.0, scale_y = 1.0;
  Eigen::Matrix2d matrix() const {
    const double a = angle_deg * M_PI / 180.0, b = a + skew_deg * M_PI / 180.0;
    Eigen::Matrix2d g;
    g << scale_x * std::cos(a), -scale_y * std::sin(b), scale_x * std::sin(a), scale_y * std::cos(b);
    return g;
  }
};

nlohmann::json map_json(const vs::AffineMap& m) {
  const vs::AffineFigures f = vs::affine_figures(m);
  return {{"A_px_per_m", {{m.A(0, 0), m.A(0, 1)}, {m.A(1, 0), m.A(1, 1)}}},
          {"b_px", {m.b.x(), m.b.y()}},
          {"um_per_px_x", f.um_per_px_x},
          {"um_per_px_y", f.um_per_px_y},
          {"rotation_deg", f.rotation_rad * 180.0 / M_PI},
          {"shear_deg", f.shear_rad * 180.0 / M_PI},
          {"mirrored", f.mirrored}};
}

// ---- calibrate ----------------------------------------------------------------------------
struct CalibrateOptions {
  CommonOptions common;
  std::optional<std::filesystem::path> save;
  CameraOptions camera;
  int grid = 5;
  std::optional<double> pitch_um;
  double opening_um = 20.0;
  StageGeometry geometry;
};

void run_calibrate(const CalibrateOptions& o) {
  const pf::PlatformConfig config = pf::scene_config(o.camera.scene);
  imaging::CameraParams cam = camera_for(o.camera);
  pf::CameraScenePose pose = pf::initial_pose(config);
  pose.opening_m = o.opening_um * 1e-6;
  const Eigen::Vector2d home(pose.tool_x_m, pose.tool_y_m);
  cam.view_center_x_m = home.x();
  cam.view_center_y_m = home.y();
  imaging::Renderer renderer(cam);
  imaging::CameraControls controls = renderer.default_controls();
  controls.focus_z_m = pose.tool_z_m;  // the finger tips in focus
  const double pixel_m = cam.pixel_size_m();
  // Default pitch: the grid spans half the field's short side.
  const double fov_m = std::min(cam.sensor.width_px, cam.sensor.height_px) * pixel_m;
  const double pitch_m = o.pitch_um ? *o.pitch_um * 1e-6 : 0.5 * fov_m / (o.grid - 1);
  const Eigen::Matrix2d g = o.geometry.matrix();
  imaging::SceneSnapshot scene;
  imaging::Frame frame;
  const auto frame_at = [&](const Eigen::Vector2d& stage_m, std::uint64_t index) {
    const Eigen::Vector2d world = home + g * (stage_m - home);
    pose.tool_x_m = world.x();
    pose.tool_y_m = world.y();
    pf::fill_camera_scene(config, pose, scene);
    // Calibrated on the bare substrate (before the parts are laid out): a part passing under the
    // gap between the tips would change what the template sees.
    scene.parts.clear();
    scene.holes.clear();
    scene.beads.clear();
    renderer.render(scene, controls, o.camera.seed, index, frame);
  };
  // The template: the finger tips and the gap between them, at the home.
  frame_at(home, 0);
  const double tip_v = renderer.v_of_y(home.y()) - 0.25 * o.camera.template_px;
  vs::TemplateTracker tracker;
  tracker.set_template(frame, centred_roi(renderer.u_of_x(home.x()), tip_v, o.camera.template_px, cam));
  const Eigen::Vector2d template_px(tracker.last().u_px, tracker.last().v_px);
  const std::string first_png = imaging::encode_png(frame);

  const std::vector<Eigen::Vector2d> stage = vs::calibration_grid(home, o.grid, pitch_m);
  std::vector<Eigen::Vector2d> pixel;
  CsvTable points({"stage_x_m", "stage_y_m", "u_px", "v_px", "confidence"});
  for (std::size_t k = 0; k < stage.size(); ++k) {
    frame_at(stage[k], k + 1);
    // Searched where the objective's nominal scale puts it (the stage's geometry is what is measured).
    const Eigen::Vector2d nominal =
        template_px + Eigen::Vector2d(1.0, -1.0).cwiseProduct(stage[k] - home) / pixel_m;
    const vs::TrackEstimate e = tracker.track_near(frame, nominal.x(), nominal.y());
    if (!e.found)
      throw mc::ComputationFailed(fmt::format(
          "calibration: the tool was lost at grid point {} (correlation {:.2f}); try a smaller --pitch-um", k,
          e.confidence));
    pixel.emplace_back(e.u_px, e.v_px);
    const double row[] = {stage[k].x(), stage[k].y(), e.u_px, e.v_px, e.confidence};
    points.add_row(row);
    progress("calibrate", k + 1, stage.size());
  }
  const vs::AffineFit fit = vs::fit_affine(stage, pixel);
  // The truth: the tracked point moves with the tool by G ds, seen at 1/pixel through the flip.
  vs::AffineMap truth;
  truth.A = (Eigen::Matrix2d() << 1.0, 0.0, 0.0, -1.0).finished() * g / pixel_m;
  truth.b = template_px - truth.A * home;
  const vs::AffineFigures ff = vs::affine_figures(fit.map), tf = vs::affine_figures(truth);
  const double scale_err_x = ff.um_per_px_x / tf.um_per_px_x - 1.0;
  const double scale_err_y = ff.um_per_px_y / tf.um_per_px_y - 1.0;
  std::vector<double> residual_u, residual_v;
  for (const Eigen::Vector2d& r : fit.residuals_px) {
    residual_u.push_back(r.x());
    residual_v.push_back(r.y());
  }
  points.add_column("residual_u_px", residual_u);
  points.add_column("residual_v_px", residual_v);

  nlohmann::json j = {{"scene", o.camera.scene},
                      {"objective", cam.objective.name},
                      {"grid", o.grid},
                      {"pitch_m", pitch_m},
                      {"points", stage.size()},
                      {"map", map_json(fit.map)},
                      {"truth", map_json(truth)},
                      {"residual_rms_px", fit.residual_rms_px},
                      {"residual_max_px", fit.residual_max_px},
                      {"scale_error_x", scale_err_x},
                      {"scale_error_y", scale_err_y},
                      {"rotation_error_deg", (ff.rotation_rad - tf.rotation_rad) * 180.0 / M_PI},
                      {"shear_error_deg", (ff.shear_rad - tf.shear_rad) * 180.0 / M_PI},
                      {"stage_geometry",
                       {{"angle_deg", o.geometry.angle_deg},
                        {"skew_deg", o.geometry.skew_deg},
                        {"scale_x", o.geometry.scale_x},
                        {"scale_y", o.geometry.scale_y}}},
                      {"seed", o.camera.seed}};
  if (o.save) {
    // The configuration's form (platform configuration: camera.calibrations), for --config/--params.
    const vs::StageCalibration c = vs::StageCalibration::of(cam.objective.name, fit);
    write_file_atomic(
        *o.save,
        fmt::format("# microcobot vision calibrate: {} points, residual {:.4f} px rms\n"
                    "camera:\n  calibrations:\n    - objective: {}\n"
                    "      px_per_m: [[{:.10g}, {:.10g}], [{:.10g}, {:.10g}]]\n"
                    "      offset_px: [{:.10g}, {:.10g}]\n      residual_rms_px: {:.6g}\n",
                    stage.size(), fit.residual_rms_px, c.objective, c.px_per_m[0][0], c.px_per_m[0][1],
                    c.px_per_m[1][0], c.px_per_m[1][1], c.offset_px[0], c.offset_px[1], c.residual_rms_px));
  }
  if (o.common.out) {
    ensure_writable_dir(*o.common.out);
    write_csv(*o.common.out / "points.csv", points,
              {"calibration grid: commanded stage point, tracked template centre, fit residual"});
    write_file_atomic(*o.common.out / "frame-home.png", first_png);
    write_file_atomic(*o.common.out / "calibration.json", j.dump(2) + "\n");
  }
  emit(
      o.common, j,
      fmt::format("{} points, {} um pitch, {}: {:.5f} x {:.5f} um/px, rotation {:.3f} deg, shear {:.3f} deg\n"
                  "residual rms {:.3f} px, max {:.3f} px; scale error x {:+.3f} %, y {:+.3f} % of the truth",
                  stage.size(), pitch_m * 1e6, cam.objective.name, ff.um_per_px_x, ff.um_per_px_y,
                  ff.rotation_rad * 180.0 / M_PI, ff.shear_rad * 180.0 / M_PI, fit.residual_rms_px,
                  fit.residual_max_px, 100.0 * scale_err_x, 100.0 * scale_err_y));
}

// ---- track --------------------------------------------------------------------------------
struct TrackOptions {
  CommonOptions common;
  CameraOptions camera;
  std::string target = "part";
  int frames = 60;
  double speed_um_s = 20.0;
  double direction_deg = 30.0;
  std::optional<double> highpass_px;
  double template_above_px = 0.0;
  std::optional<double> template_um;  ///< --template-um: the side in the object
  bool template_px_given = false;     ///< --template-px given (else the side comes from the objective)
};

void run_track(const TrackOptions& o) {
  const pf::PlatformConfig config = pf::scene_config(o.camera.scene);
  imaging::CameraParams cam = camera_for(o.camera);
  pf::CameraScenePose pose = pf::initial_pose(config);
  const bool tool = o.target == "tool";
  const Eigen::Vector2d start =
      tool ? Eigen::Vector2d(pose.tool_x_m, pose.tool_y_m) : Eigen::Vector2d(pose.part_x_m, pose.part_y_m);
  if (tool) pose.opening_m = 20e-6;
  cam.view_center_x_m = start.x();
  cam.view_center_y_m = start.y();
  imaging::Renderer renderer(cam);
  imaging::CameraControls controls = renderer.default_controls();
  controls.focus_z_m = pose.tool_z_m;
  const double dt = 1.0 / cam.sensor.frame_rate_Hz;
  const Eigen::Vector2d velocity =
      o.speed_um_s * 1e-6 *
      Eigen::Vector2d(std::cos(o.direction_deg * M_PI / 180.0), std::sin(o.direction_deg * M_PI / 180.0));
  imaging::SceneSnapshot scene;
  imaging::Frame frame;
  const auto frame_at = [&](const Eigen::Vector2d& p, std::uint64_t index) {
    (tool ? pose.tool_x_m : pose.part_x_m) = p.x();
    (tool ? pose.tool_y_m : pose.part_y_m) = p.y();
    pf::fill_camera_scene(config, pose, scene);
    renderer.render(scene, controls, o.camera.seed, index, frame);
  };
  frame_at(start, 0);
  if (!tool && !scene.parts.empty()) {  // the part's top face in focus
    controls.focus_z_m = scene.parts.front().z_top_m;
    frame_at(start, 0);
  }
  // The part: its upper left corner (two edges; its face is uniform); the tool: its tips, their
  // ends and the gap between them, centred on the tool point. The ends' edges fix the rows: a
  // template a quarter of its side higher held only the fingers' sides and the gap (worst 0.45 px
  // over seeded cases, docs/benchmarks.md).
  double u0 = renderer.u_of_x(start.x()), v0 = renderer.v_of_y(start.y()) - o.template_above_px;
  if (!tool) {
    if (scene.parts.empty())
      throw mc::InvalidInput("--target part: the scene " + o.camera.scene + " has no part");
    u0 = renderer.u_of_x(start.x() - 0.5 * scene.parts.front().size_x_m);
    v0 = renderer.v_of_y(start.y() + 0.5 * scene.parts.front().size_y_m);
  }
  vs::TrackerParams params;
  // The tips stand 150 um over the part: its defocused glow, under the gap, changes as the tool
  // moves. A high-pass of 1.5 px takes it out of the alignment (chosen on the tuning cases:
  // docs/parameters.md "Tracking the tool's tips").
  params.ecc_highpass_px = o.highpass_px.value_or(tool ? vs::kToolTipHighpass_px : 0.0);
  vs::TemplateTracker tracker(params);
  // The side: as given in pixels; or in the object (--template-um; the tool's tips by default), in
  // the objective's pixels.
  int side_px = o.camera.template_px;
  if (!o.template_px_given && (o.template_um || tool))
    side_px = vs::template_side_px(o.template_um ? *o.template_um * 1e-6 : vs::kToolTemplateSide_m,
                                   cam.pixel_size_m(), cam.sensor.width_px, cam.sensor.height_px);
  imaging::PixelRoi roi;
  try {
    roi = centred_roi(u0, v0, side_px, cam);
  } catch (const mc::InvalidInput& e) {
    if (tool && o.template_above_px != 0.0)
      throw mc::InvalidInput(fmt::format("--template-above-px {:g}: {}", o.template_above_px, e.what()));
    if (o.template_um)
      throw mc::InvalidInput(fmt::format("--template-um {:g} ({} px at {}): {}", *o.template_um, side_px,
                                         cam.objective.name, e.what()));
    throw;
  }
  tracker.set_template(frame, roi);
  const double u_off = tracker.last().u_px - renderer.u_of_x(start.x());
  const double v_off = tracker.last().v_px - renderer.v_of_y(start.y());

  CsvTable rows(
      {"t_s", "true_u_px", "true_v_px", "u_px", "v_px", "error_u_px", "error_v_px", "confidence", "found"});
  double sum2 = 0.0, worst = 0.0, bias_u = 0.0, bias_v = 0.0;
  int found = 0;
  for (int k = 1; k <= o.frames; ++k) {
    const Eigen::Vector2d p = start + velocity * (k * dt);
    frame_at(p, static_cast<std::uint64_t>(k));
    const vs::TrackEstimate e = tracker.track(frame);
    const double tu = renderer.u_of_x(p.x()) + u_off, tv = renderer.v_of_y(p.y()) + v_off;
    const double eu = e.u_px - tu, ev = e.v_px - tv;
    if (e.found) {
      ++found;
      sum2 += eu * eu + ev * ev;
      worst = std::max(worst, std::hypot(eu, ev));
      bias_u += eu;
      bias_v += ev;
    }
    const double row[] = {k * dt, tu, tv, e.u_px, e.v_px, eu, ev, e.confidence, e.found ? 1.0 : 0.0};
    rows.add_row(row);
  }
  if (found == 0) throw mc::ComputationFailed("track: the target was lost in every frame");
  const double n = found;
  const double rms = std::sqrt(sum2 / n);
  nlohmann::json j = {{"scene", o.camera.scene},
                      {"objective", cam.objective.name},
                      {"target", o.target},
                      {"frames", o.frames},
                      {"found", found},
                      {"speed_m_s", o.speed_um_s * 1e-6},
                      {"direction_deg", o.direction_deg},
                      {"template_px", side_px},
                      {"highpass_px", params.ecc_highpass_px},
                      {"rms_error_px", rms},
                      {"max_error_px", worst},
                      {"bias_px", {bias_u / n, bias_v / n}},
                      {"rms_error_m", rms * cam.pixel_size_m()},
                      {"seed", o.camera.seed}};
  write_result_table(o.common, "track.csv", rows, j);
  emit(o.common, j,
       fmt::format("{} over {} frames at {:g} um/s ({}): found in {}, error rms {:.4f} px ({:.1f} nm), max "
                   "{:.4f} px, bias ({:+.4f}, {:+.4f}) px",
                   o.target, o.frames, o.speed_um_s, cam.objective.name, found, rms,
                   rms * cam.pixel_size_m() * 1e9, worst, bias_u / n, bias_v / n));
}

}  // namespace

void add_vision_processing(CLI::App& group) {
  {
    auto o = std::make_shared<CalibrateOptions>();
    auto* cmd = group.add_subcommand(
        "calibrate", "Pixel <-> stage affine map: the tool moved through a grid, its tips tracked");
    add_camera_options(*cmd, o->camera);
    cmd->add_option("--grid", o->grid, "Grid points per side (default 5)")->check(CLI::Range(2, 21));
    cmd->add_option("--pitch-um", o->pitch_um, "Grid pitch [um] (default: the grid spans half the field)")
        ->check(mc::cli::Range(0.01, 1e4));
    cmd->add_option("--opening-um", o->opening_um,
                    "Gripper opening: the gap tracked between the tips (default 20)")
        ->check(mc::cli::Range(0.0, 1e3));
    cmd->add_option("--axis-angle-deg", o->geometry.angle_deg,
                    "Simulated stage: its x axis's angle in the image (default 0)")
        ->check(mc::cli::Range(-180.0, 180.0));
    cmd->add_option("--skew-deg", o->geometry.skew_deg,
                    "Simulated stage: non-orthogonality of y to x (default 0)")
        ->check(mc::cli::Range(-10.0, 10.0));
    cmd->add_option("--scale-x", o->geometry.scale_x,
                    "Simulated stage: x travel per commanded metre (default 1)")
        ->check(mc::cli::Range(0.5, 2.0));
    cmd->add_option("--scale-y", o->geometry.scale_y,
                    "Simulated stage: y travel per commanded metre (default 1)")
        ->check(mc::cli::Range(0.5, 2.0));
    cmd->add_option(
        "--save", o->save,
        "Write the calibration as a platform configuration fragment (camera.calibrations) to FILE");
    add_output_options(*cmd, o->common);
    cmd->callback([o] { run_calibrate(*o); });
  }
  {
    auto o = std::make_shared<TrackOptions>();
    auto* cmd = group.add_subcommand(
        "track", "A part or the tool followed by the template tracker, against the simulation's truth");
    add_camera_options(*cmd, o->camera);
    cmd->add_option("--target", o->target, "part (default) or tool")->check(CLI::IsMember({"part", "tool"}));
    cmd->add_option("--frames", o->frames, "Frames tracked (default 60)")->check(CLI::Range(1, 100000));
    cmd->add_option("--speed-um-s", o->speed_um_s, "Target speed [um/s] (default 20)")
        ->check(mc::cli::Range(0.0, 1e4));
    cmd->add_option("--direction-deg", o->direction_deg, "Direction of motion, from stage x (default 30)")
        ->check(mc::cli::Range(-360.0, 360.0));
    cmd->add_option(
           "--highpass-px", o->highpass_px,
           "The tracker's high-pass before ECC, a Gaussian's sigma [px], 0 none (default: 1.5 for the "
           "tool, 0 for the part)")
        ->check(mc::cli::Range(0.0, 64.0));
    cmd->add_option(
           "--template-above-px", o->template_above_px,
           "The tool's template this far above the tool point [px] (default 0: the tips' ends in it)")
        ->check(mc::cli::Range(-1000.0, 1000.0));
    auto* um = cmd->add_option("--template-um", o->template_um,
                               "Side of the tracked template in the object [um], in the objective's pixels "
                               "(default for the tool: 50 um, at least 96 px)")
                   ->check(mc::cli::Range(1.0, 10000.0));
    CLI::Option* px = cmd->get_option("--template-px");
    um->excludes(px);
    add_output_options(*cmd, o->common);
    cmd->callback([o, px] {
      o->template_px_given = px->count() > 0;
      run_track(*o);
    });
  }
  add_vision_autofocus(group);
}

}  // namespace mc::cli
