// `microcobot vision autofocus`: the steppable coarse-to-fine search
// (vision/autofocus.h) run frame by frame on rendered frames, from a start off the truth, and
// judged against it: a part's top or the tool's tips.

#include <algorithm>
#include <cmath>
#include <optional>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/imaging/renderer.h"
#include "microcobot/platform/camera_scene.h"
#include "microcobot/vision/autofocus.h"
#include "microcobot/vision/sharpness.h"
#include "vision_camera_options.h"
#include "vision_processing_commands.h"

namespace mc::cli {
namespace {

namespace vs = mc::vision;
namespace pf = mc::platform;

struct AutofocusOptions {
  CommonOptions common;
  CameraOptions camera;
  std::string target = "part";
  double offset_um = 100.0;
  std::string metric;
  int coarse_px = -1;  // -1: by the target (kToolCoarsePx for the tool, the measured region for a part)
};

// The tool's coarse scan measures a square this many pixels wide around the tips (clipped to the
// frame): the strip sees the tips only within +-16 um at 50x (+-40 um at 20x), the wider square sees
// their silhouette from +-60-100 um. Chosen on noise seed 1 among 0 (the strip), 192 and 384 px
// (docs/benchmarks.md, "tool's tips").
constexpr int kToolCoarsePx = 192;

imaging::PixelRoi square_in_frame(double u, double v, int side, const imaging::CameraParams& cam) {
  const int w = std::min(side, cam.sensor.width_px), h = std::min(side, cam.sensor.height_px);
  const int x = std::clamp(static_cast<int>(std::lround(u - 0.5 * (w - 1))), 0, cam.sensor.width_px - w);
  const int y = std::clamp(static_cast<int>(std::lround(v - 0.5 * (h - 1))), 0, cam.sensor.height_px - h);
  return {x, y, w, h};
}

void run_autofocus(const AutofocusOptions& o) {
  const pf::PlatformConfig config = pf::scene_config(o.camera.scene);
  imaging::CameraParams cam = camera_for(o.camera);
  pf::CameraScenePose pose = pf::initial_pose(config);
  const bool tool = o.target == "tool";
  if (tool) pose.opening_m = 20e-6;  // both tips in the view
  imaging::SceneSnapshot scene;
  pf::fill_camera_scene(config, pose, scene);
  if (!tool && scene.parts.empty())
    throw mc::InvalidInput("--target part: the scene " + o.camera.scene + " has no part");
  // The truth: the part's top, or the tips' height. The measured region holds one surface, and the
  // view is centred on it: the middle of the part's near edge (its top face is uniform: the edge
  // carries the focus; the gripper's fingers reach in from the far side), or a strip across the
  // left tip's end an eighth of the template high (the fingers rise along their length).
  const double truth_m = tool ? pose.tool_z_m : scene.parts.front().z_top_m;
  const imaging::Finger& finger = scene.fingers.front();
  const Eigen::Vector2d target =
      tool ? Eigen::Vector2d(finger.tip_x_m, finger.tip_y_m)
           : Eigen::Vector2d(pose.part_x_m, pose.part_y_m - 0.5 * scene.parts.front().size_y_m);
  cam.view_center_x_m = target.x();
  cam.view_center_y_m = target.y();
  imaging::Renderer renderer(cam);
  imaging::CameraControls controls = renderer.default_controls();
  imaging::PixelRoi roi =
      centred_roi(renderer.u_of_x(target.x()), renderer.v_of_y(target.y()), o.camera.template_px, cam);
  if (tool) {
    // A strip an eighth of the template high (12 px of 96) centred on the tips' end: half of it
    // beyond the end, half on the finger, whose face rises along its length; a quarter (24 px) read
    // the tips 1.3-1.5 um high at 10x from the finger's face (chosen on noise seed 1, strips of 6, 12
    // and 24 px; docs/benchmarks.md, "tool's tips").
    roi.y += 7 * o.camera.template_px / 16;
    roi.height = o.camera.template_px / 8;
  }
  std::optional<vs::FocusMetric> metric;
  if (!o.metric.empty()) {
    try {
      metric = vs::parse_focus_metric(o.metric);
    } catch (const mc::InvalidInput& e) {
      throw mc::UsageError(std::string("--metric: ") + e.what());
    }
  }
  vs::AutofocusParams params =
      metric ? vs::autofocus_params_for(renderer.figures(), truth_m + o.offset_um * 1e-6, *metric)
             : vs::autofocus_params_for(renderer.figures(), truth_m + o.offset_um * 1e-6);
  // The search may go wherever the focus drive goes (devices/camera_device.h).
  params.range_min_m = std::min(config.camera.focus_min_m, params.start_m);
  params.range_max_m = std::max(config.camera.focus_max_m, params.start_m);
  const int coarse_px = o.coarse_px >= 0 ? o.coarse_px : (tool ? kToolCoarsePx : 0);
  const imaging::PixelRoi coarse_roi =
      coarse_px > 0
          ? square_in_frame(renderer.u_of_x(target.x()), renderer.v_of_y(target.y()), coarse_px, cam)
          : roi;
  params.reuse_coarse_samples = coarse_px == 0;
  vs::Autofocus search(params);
  imaging::Frame frame;
  CsvTable rows({"frame", "focus_z_m", "sharpness"});
  std::uint64_t index = 0;
  while (!search.done()) {
    controls.focus_z_m = search.next_focus_m();
    renderer.render(scene, controls, o.camera.seed, index, frame);
    const double measure =
        vs::sharpness(frame, search.next_is_coarse() ? coarse_roi : roi, search.next_metric());
    const double row[] = {static_cast<double>(index), controls.focus_z_m, measure};
    rows.add_row(row);
    search.observe(measure);
    ++index;
  }
  const double error_m = search.best_focus_m() - truth_m;
  const double dof_m = renderer.figures().dof_m;
  nlohmann::json j = {{"scene", o.camera.scene},
                      {"objective", cam.objective.name},
                      {"target", o.target},
                      {"start_offset_m", o.offset_um * 1e-6},
                      {"converged", search.converged()},
                      {"status", search.status()},
                      {"frames", search.frames_used()},
                      {"best_focus_m", search.best_focus_m()},
                      {"truth_m", truth_m},
                      {"error_m", error_m},
                      {"dof_m", dof_m},
                      {"error_dof", error_m / dof_m},
                      {"coarse_px", coarse_px},
                      {"seed", o.camera.seed}};
  write_result_table(o.common, "autofocus.csv", rows, j);
  emit(o.common, j,
       fmt::format("{} ({}), from {:+g} um: {} after {} frames ({}), best focus {:.3f} um, error {:+.3f} um "
                   "({:+.3f} DOF)",
                   o.target, cam.objective.name, o.offset_um,
                   search.converged() ? "converged" : "not converged", search.frames_used(), search.status(),
                   search.best_focus_m() * 1e6, error_m * 1e6, error_m / dof_m));
}

}  // namespace

void add_vision_autofocus(CLI::App& group) {
  auto o = std::make_shared<AutofocusOptions>();
  auto* cmd = group.add_subcommand(
      "autofocus", "The plane of best focus of a part's top or the tool's tips, searched frame by frame");
  add_camera_options(*cmd, o->camera);
  cmd->add_option("--target", o->target, "part (default: its top) or tool (its tips)")
      ->check(CLI::IsMember({"part", "tool"}));
  cmd->add_option("--offset-um", o->offset_um, "Start this far from the truth [um] (default 100)")
      ->check(mc::cli::Range(-5000.0, 5000.0));
  cmd->add_option("--metric", o->metric,
                  "Fine focus measure: normalized-variance, tenengrad, brenner (default: by the objective)");
  cmd->add_option("--coarse-px", o->coarse_px,
                  "The coarse scan's square region around the target [px] (0: the measured region itself; "
                  "default: 192 for the tool, 0 for a part)")
      ->check(CLI::Range(0, 1 << 16));
  add_output_options(*cmd, o->common);
  cmd->callback([o] { run_autofocus(*o); });
}

}  // namespace mc::cli
