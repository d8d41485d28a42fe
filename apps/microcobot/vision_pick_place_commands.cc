// `microcobot vision pick-place`: a pick-and-place done by the visual servo
// alone, the stage's encoders off, over a seeded random set of starts and targets judged against
// the simulation's truth (studies/visual_pick_place_run.h).

#include <algorithm>
#include <cmath>
#include <random>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/studies/visual_pick_place_run.h"
#include "vision_processing_commands.h"

namespace mc::cli {
namespace {

struct PickPlaceOptions {
  CommonOptions common;
  studies::VisualPickPlaceParams run;
  int runs = 1;
  std::uint64_t set_seed = 1;
  int sensor_px = 0;
};

void run_pick_place(const PickPlaceOptions& o) {
  // The set: per run, the target 400-550 um away along +-x and within +-100 um in y, the tool's
  // start 250-350 um beyond the part along +y (the fingers, which reach up the image from the
  // tips, then clear the part in the first frame) and within +-150 um in x, its own noise seed.
  // Set seed 1 is the one the sequence was set up on, 2 the validation set (docs/benchmarks.md).
  std::mt19937_64 rng(o.set_seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  CsvTable frames({"run", "frame", "phase", "t_mid_s", "tool_x_m", "tool_y_m", "tool_z_m", "part_x_m",
                   "part_y_m", "part_z_m", "u_px", "v_px", "confidence", "found", "servo_error_m", "vx_m_s",
                   "vy_m_s", "grip_force_N"});
  CsvTable summary({"run", "target_dx_m", "target_dy_m", "placement_error_m", "completed", "holding",
                    "approach_frames", "transport_frames", "duration_s"});
  nlohmann::json runs = nlohmann::json::array();
  double worst = 0.0;
  int failed = 0, not_holding = 0;
  std::string first_png, grasp_png, last_png;
  for (int s = 0; s < o.runs; ++s) {
    studies::VisualPickPlaceParams p = o.run;
    const double sx = u01(rng) < 0.5 ? -1.0 : 1.0;
    p.target_offset_m = {sx * (400e-6 + 150e-6 * u01(rng)), 200e-6 * (u01(rng) - 0.5)};
    p.start_offset_m = {300e-6 * (u01(rng) - 0.5), 250e-6 + 100e-6 * u01(rng)};
    p.seed = o.run.seed + 1000 * o.set_seed + static_cast<std::uint64_t>(s);
    p.width_px = p.height_px = o.sensor_px;
    const studies::VisualPickPlaceResult r = studies::run_visual_pick_place(p);
    for (std::size_t k = 0; k < r.frames.size(); ++k) {
      const studies::PickPlaceFrame& f = r.frames[k];
      const double row[] = {static_cast<double>(s),
                            static_cast<double>(k),
                            static_cast<double>(f.phase),
                            f.t_mid_s,
                            f.tool_m.x(),
                            f.tool_m.y(),
                            f.tool_m.z(),
                            f.part_m.x(),
                            f.part_m.y(),
                            f.part_m.z(),
                            f.u_px,
                            f.v_px,
                            f.confidence,
                            f.found ? 1.0 : 0.0,
                            f.servo_error_m.norm(),
                            f.velocity_m_s.x(),
                            f.velocity_m_s.y(),
                            f.grip_force_N};
      frames.add_row(row);
    }
    const double err = r.placement_error_m.norm();
    const bool holding = r.xy_holding && r.z_holding && r.gripper_holding;
    const double srow[] = {static_cast<double>(s),
                           p.target_offset_m.x(),
                           p.target_offset_m.y(),
                           err,
                           r.completed ? 1.0 : 0.0,
                           holding ? 1.0 : 0.0,
                           static_cast<double>(r.approach_frames),
                           static_cast<double>(r.transport_frames),
                           r.duration_s};
    summary.add_row(srow);
    if (r.completed && r.part_on_substrate) {
      worst = std::max(worst, err);
    } else {
      ++failed;
    }
    if (!holding) ++not_holding;
    runs.push_back({{"target_offset_m", {p.target_offset_m.x(), p.target_offset_m.y()}},
                    {"start_offset_m", {p.start_offset_m.x(), p.start_offset_m.y()}},
                    {"completed", r.completed},
                    {"failed_phase", r.completed ? "" : studies::to_string(r.failed_phase)},
                    {"part_on_substrate", r.part_on_substrate},
                    {"placement_error_m", err},
                    {"grasp_error_m", r.grasp_error_m.norm()},
                    {"approach_frames", r.approach_frames},
                    {"transport_frames", r.transport_frames},
                    {"duration_s", r.duration_s},
                    {"holding", {{"xy", r.xy_holding}, {"z", r.z_holding}, {"gripper", r.gripper_holding}}}});
    if (s == 0) {
      first_png = r.first_png;
      grasp_png = r.grasp_png;
      last_png = r.last_png;
    }
    progress("pick-place", static_cast<std::size_t>(s + 1), static_cast<std::size_t>(o.runs));
  }
  nlohmann::json j = {{"scene", o.run.scene},
                      {"objective", o.run.objective},
                      {"runs", o.runs},
                      {"set_seed", o.set_seed},
                      {"calibration_scale_error", o.run.calibration_scale_error},
                      {"sensor", "vision (XY encoders off; Z its own controller)"},
                      {"max_placement_error_m", worst},
                      {"failed", failed},
                      {"not_holding", not_holding},
                      {"results", runs}};
  if (o.common.out) {
    ensure_writable_dir(*o.common.out);
    write_csv(
        *o.common.out / "pick-place.csv", frames,
        {"pick-and-place by the visual servo alone, encoders off: per frame (phase 0 approach, 1 descend, 2 "
         "grasp, 3 lift, 4 transport, 5 lower, 6 release, 7 retract), truth and servo"});
    write_csv(*o.common.out / "runs.csv", summary, {"per run: the part's placement error at rest"});
    write_file_atomic(*o.common.out / "frame-first.png", first_png);
    if (!grasp_png.empty()) write_file_atomic(*o.common.out / "frame-held.png", grasp_png);
    write_file_atomic(*o.common.out / "frame-last.png", last_png);
    write_file_atomic(*o.common.out / "pick-place.json", j.dump(2) + "\n");
  }
  emit(o.common, j,
       fmt::format(
           "{} pick-and-place(s) by the servo alone ({}, set seed {}, calibration error {:+.1f} %): placed "
           "within {:.3f} um, {} failed, {} not holding at the end",
           o.runs, o.run.objective, o.set_seed, 100.0 * o.run.calibration_scale_error, worst * 1e6, failed,
           not_holding));
}

}  // namespace

void add_vision_pick_place(CLI::App& group) {
  auto o = std::make_shared<PickPlaceOptions>();
  auto* cmd =
      group.add_subcommand("pick-place", "A pick-and-place by the visual servo alone, the encoders off");
  cmd->add_option("--scene", o->run.scene, "pick-place (default) or a YAML scene file (its part)");
  cmd->add_option("--objective", o->run.objective, "Objective: 2x, 5x (default), 10x, 20x, 50x");
  cmd->add_option("--seed", o->run.seed, "Seed of the sensor noise (default 1)");
  cmd->add_option("--runs", o->runs, "Runs of the seeded random set (default 1)")->check(CLI::Range(1, 1000));
  cmd->add_option("--set-seed", o->set_seed,
                  "Seed of the set of starts and targets (default 1: tuning; 2: validation)");
  cmd->add_option("--calibration-error", o->run.calibration_scale_error,
                  "The servo's calibration scale error, x (1 + e), y (1 - e) (default 0)")
      ->check(mc::cli::Range(-0.4, 0.4));
  cmd->add_option("--phase-frames", o->run.phase_frames,
                  "A servo phase not converged in this many frames fails, holding (default 200)")
      ->check(CLI::Range(3, 10000));
  cmd->add_option("--sensor-px", o->sensor_px, "Square sensor of this many pixels (default: 1280x1024)")
      ->check(CLI::Range(64, 4096));
  add_output_options(*cmd, o->common);
  cmd->callback([o] { run_pick_place(*o); });
}

}  // namespace mc::cli
