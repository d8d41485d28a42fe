// `microcobot vision force|servo`: the grip force measured from the fingers'
// deflection in the image, and the gripper's tips brought over the part by image-based visual
// servoing with the stage's encoders off; each over a seeded random set judged against the
// simulation's truth.

#include <algorithm>
#include <cmath>
#include <random>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/studies/force_by_vision_run.h"
#include "microcobot/studies/visual_servo_run.h"
#include "vision_processing_commands.h"

namespace mc::cli {
namespace {

namespace vs = mc::vision;

struct ServoOptions {
  CommonOptions common;
  studies::ServoRunParams run;
  double distance_um = 50.0;
  int starts = 1;
  std::uint64_t start_seed = 1;
  double gain = 40.0;
  int sensor_px = 0;
  double latency_ms = 10.0;
};

void run_servo(const ServoOptions& o) {
  if (!std::isfinite(o.gain) || o.gain <= 0.0)
    throw mc::InvalidParams("--gain", "must be finite and > 0 1/s", o.gain);
  // The starts: `distance_um` from the goal in seeded random directions, each with its own
  // sensor-noise seed (the start seed picks the set: 1 tunes, 2 validates; docs/benchmarks.md).
  std::mt19937_64 rng(o.start_seed);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI);
  CsvTable frames({"start", "frame", "t_mid_s", "true_error_x_m", "true_error_y_m", "true_error_m",
                   "servo_error_m", "vx_m_s", "vy_m_s", "u_px", "v_px", "confidence", "found", "periods_x",
                   "periods_y"});
  CsvTable summary({"start", "direction_rad", "final_error_m", "converged_frame"});
  nlohmann::json runs = nlohmann::json::array();
  double worst_final = 0.0;
  int worst_frames = -1, not_converged = 0;
  std::string first_png, last_png;
  for (int s = 0; s < o.starts; ++s) {
    studies::ServoRunParams p = o.run;
    const double a = angle(rng);
    p.start_offset_m = o.distance_um * 1e-6 * Eigen::Vector2d(std::cos(a), std::sin(a));
    p.seed = o.run.seed + 1000 * o.start_seed + static_cast<std::uint64_t>(s);
    p.servo.gain_per_s = o.gain;
    p.width_px = p.height_px = o.sensor_px;
    p.processing_latency_s = o.latency_ms * 1e-3;
    const studies::ServoRunResult r = studies::run_visual_servo(p);
    for (std::size_t k = 0; k < r.frames.size(); ++k) {
      const studies::ServoFrame& f = r.frames[k];
      const double row[] = {static_cast<double>(s),
                            static_cast<double>(k),
                            f.t_mid_s,
                            f.true_error_m.x(),
                            f.true_error_m.y(),
                            f.true_error_m.norm(),
                            f.servo_error_m.norm(),
                            f.velocity_m_s.x(),
                            f.velocity_m_s.y(),
                            f.u_px,
                            f.v_px,
                            f.confidence,
                            f.found ? 1.0 : 0.0,
                            static_cast<double>(f.periods_x),
                            static_cast<double>(f.periods_y)};
      frames.add_row(row);
    }
    const double fin = r.final_error_m.norm();
    const double srow[] = {static_cast<double>(s), a, fin, static_cast<double>(r.converged_frame)};
    summary.add_row(srow);
    worst_final = std::max(worst_final, fin);
    if (r.converged_frame < 0) ++not_converged;
    worst_frames = std::max(worst_frames, r.converged_frame);
    runs.push_back({{"direction_rad", a}, {"final_error_m", fin}, {"converged_frame", r.converged_frame}});
    if (s == 0) {
      first_png = r.first_png;
      last_png = r.last_png;
    }
    progress("servo", static_cast<std::size_t>(s + 1), static_cast<std::size_t>(o.starts));
  }
  nlohmann::json j = {{"scene", o.run.scene},
                      {"objective", o.run.objective},
                      {"distance_m", o.distance_um * 1e-6},
                      {"starts", o.starts},
                      {"start_seed", o.start_seed},
                      {"gain_per_s", o.gain},
                      {"calibration_scale_error", o.run.calibration_scale_error},
                      {"latency_s", o.latency_ms * 1e-3},
                      {"frames", o.run.max_frames},
                      {"sensor", "vision (encoders off)"},
                      {"max_final_error_m", worst_final},
                      {"max_converged_frame", not_converged > 0 ? -1 : worst_frames},
                      {"not_converged", not_converged},
                      {"runs", runs}};
  if (o.common.out) {
    ensure_writable_dir(*o.common.out);
    write_csv(*o.common.out / "servo.csv", frames,
              {"visual servoing, encoders off: per frame, the true and predicted errors and the command"});
    write_csv(*o.common.out / "starts.csv", summary,
              {"per start: final error at rest, frame of convergence"});
    write_file_atomic(*o.common.out / "frame-first.png", first_png);
    write_file_atomic(*o.common.out / "frame-last.png", last_png);
    write_file_atomic(*o.common.out / "servo.json", j.dump(2) + "\n");
  }
  emit(
      o.common, j,
      fmt::format("{} start(s) {:g} um from the goal ({}, gain {:g} 1/s, calibration error {:+.1f} %): final "
                  "error <= {:.3f} um, converged by frame {} ({} not converged)",
                  o.starts, o.distance_um, o.run.objective, o.gain, 100.0 * o.run.calibration_scale_error,
                  worst_final * 1e6, not_converged > 0 ? -1 : worst_frames, not_converged));
}

// ---- force ----------------------------------------------------------------------------------
struct ForceOptions {
  CommonOptions common;
  std::string objective = "10x";
  int scenes = 12;
  std::uint64_t set_seed = 2;
  double min_mN = 1.0, max_mN = 20.0;
  int loaded_frames = 16;
  int sensor_px = 0;
};

void run_force(const ForceOptions& o) {
  if (!(o.max_mN >= o.min_mN)) throw mc::InvalidParams("--max-mN", "must be >= --min-mN", o.max_mN);
  // The scenes: force uniform in [min, max], the finger stiffness in [50, 200] N/m (at least what
  // squeezes that force on a part of at most 480 um: wider, the open tips leave the 10x field), the
  // part's width, place and texture; the set
  // seed picks the set (1: the one the templates were shaped on, 2: validation).
  std::mt19937_64 rng(o.set_seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  CsvTable rows({"scene", "finger_stiffness_N_m", "part_width_m", "true_force_N", "mean_force_N", "bias_N",
                 "bias_relative", "force_noise_N", "tracking_noise_m", "noise_over_k_sigma",
                 "unloaded_residual_px"});
  nlohmann::json scenes = nlohmann::json::array();
  double worst_bias = 0.0, worst_noise = 0.0;
  std::string png;
  for (int s = 0; s < o.scenes; ++s) {
    studies::ForceSceneParams p;
    p.objective = o.objective;
    p.force_N = 1e-3 * (o.min_mN + (o.max_mN - o.min_mN) * u01(rng));
    const double k_min = std::max(50.0, 2.0 * p.force_N / 470e-6);
    p.finger_stiffness_N_m = k_min + (std::max(200.0, k_min) - k_min) * u01(rng);
    const double w_min = std::max(200e-6, 2.0 * p.force_N / p.finger_stiffness_N_m + 10e-6);
    p.part_width_m = w_min + (480e-6 - w_min) * u01(rng);
    p.part_x_m = 200e-6 * (u01(rng) - 0.5);
    p.part_y_m = 200e-6 * (u01(rng) - 0.5);
    p.texture_seed = 1 + static_cast<std::uint64_t>(1e6 * u01(rng));
    p.seed = 100 * o.set_seed + static_cast<std::uint64_t>(s);
    p.loaded_frames = o.loaded_frames;
    p.width_px = p.height_px = o.sensor_px;
    const studies::ForceSceneResult r = studies::run_force_scene(p);
    const double bias = r.mean_force_N - r.true_force_N;
    const double k_sigma = p.finger_stiffness_N_m * r.tracking_noise_m;
    const double noise_ratio = r.force_noise_N / k_sigma;
    const double row[] = {static_cast<double>(s), p.finger_stiffness_N_m,
                          p.part_width_m,         r.true_force_N,
                          r.mean_force_N,         bias,
                          bias / r.true_force_N,  r.force_noise_N,
                          r.tracking_noise_m,     noise_ratio,
                          r.unloaded_residual_px};
    rows.add_row(row);
    worst_bias = std::max(worst_bias, std::abs(bias / r.true_force_N));
    worst_noise = std::max(worst_noise, noise_ratio);
    scenes.push_back({{"finger_stiffness_N_m", p.finger_stiffness_N_m},
                      {"part_width_m", p.part_width_m},
                      {"true_force_N", r.true_force_N},
                      {"mean_force_N", r.mean_force_N},
                      {"bias_relative", bias / r.true_force_N},
                      {"force_noise_N", r.force_noise_N},
                      {"tracking_noise_m", r.tracking_noise_m},
                      {"noise_over_k_sigma", noise_ratio}});
    if (s == 0) png = r.loaded_png;
    progress("force", static_cast<std::size_t>(s + 1), static_cast<std::size_t>(o.scenes));
  }
  nlohmann::json j = {{"objective", o.objective},
                      {"scenes", o.scenes},
                      {"set_seed", o.set_seed},
                      {"force_range_N", {o.min_mN * 1e-3, o.max_mN * 1e-3}},
                      {"loaded_frames", o.loaded_frames},
                      {"max_bias_relative", worst_bias},
                      {"max_noise_over_k_sigma", worst_noise},
                      {"results", scenes}};
  if (o.common.out) {
    ensure_writable_dir(*o.common.out);
    write_csv(*o.common.out / "force.csv", rows,
              {"force by vision against the simulation's grip force, one row per scene"});
    write_file_atomic(*o.common.out / "frame-loaded.png", png);
    write_file_atomic(*o.common.out / "force.json", j.dump(2) + "\n");
  }
  emit(
      o.common, j,
      fmt::format("{} scenes, {:g}-{:g} mN ({}, set seed {}): |bias| <= {:.2f} % of the true force, noise <= "
                  "{:.2f} x k x tracking noise",
                  o.scenes, o.min_mN, o.max_mN, o.objective, o.set_seed, 100.0 * worst_bias, worst_noise));
}

}  // namespace

void add_vision_force(CLI::App& group) {
  auto o = std::make_shared<ForceOptions>();
  auto* cmd = group.add_subcommand(
      "force", "Grip force from the fingers' deflection in the image, against the simulation");
  cmd->add_option("--objective", o->objective, "Objective: 2x, 5x, 10x (default), 20x, 50x");
  cmd->add_option("--scenes", o->scenes, "Scenes of the seeded random set (default 12)")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--set-seed", o->set_seed, "Seed of the set (default 2: validation; 1: tuning)");
  cmd->add_option("--min-mN", o->min_mN, "Smallest grip force [mN] (default 1)")
      ->check(mc::cli::Range(0.01, 1000.0));
  cmd->add_option("--max-mN", o->max_mN, "Largest grip force [mN] (default 20)")
      ->check(mc::cli::Range(0.01, 1000.0));
  cmd->add_option("--frames", o->loaded_frames, "Loaded frames per scene (default 16)")
      ->check(CLI::Range(2, 10000));
  cmd->add_option("--sensor-px", o->sensor_px, "Square sensor of this many pixels (default: 1280x1024)")
      ->check(CLI::Range(64, 4096));
  add_output_options(*cmd, o->common);
  cmd->callback([o] { run_force(*o); });
}

void add_vision_servo(CLI::App& group) {
  auto o = std::make_shared<ServoOptions>();
  auto* cmd =
      group.add_subcommand("servo", "Visual servoing with the encoders off: the tips brought over the part");
  cmd->add_option("--scene", o->run.scene, "pick-place (default), pin-in-hole, or a YAML scene file");
  cmd->add_option("--objective", o->run.objective, "Objective: 2x, 5x, 10x (default), 20x, 50x");
  cmd->add_option("--seed", o->run.seed, "Seed of the sensor noise (default 1)");
  cmd->add_option("--distance-um", o->distance_um, "Start this far from the goal [um] (default 50)")
      ->check(mc::cli::Range(0.0, 2000.0));
  cmd->add_option("--starts", o->starts, "Starts in seeded random directions (default 1)")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--start-seed", o->start_seed, "Seed of the start directions (default 1: the tuning set)");
  cmd->add_option("--gain", o->gain, "Servo gain lambda [1/s] (default 40, chosen on start seed 1)");
  cmd->add_option("--calibration-error", o->run.calibration_scale_error,
                  "The servo's calibration scale error, x (1 + e), y (1 - e) (default 0)")
      ->check(mc::cli::Range(-0.4, 0.4));
  cmd->add_option("--latency-ms", o->latency_ms, "End of exposure to command [ms] (default 10)")
      ->check(mc::cli::Range(0.0, 500.0));
  cmd->add_option("--frames", o->run.max_frames, "Frames per start (default 60)")
      ->check(CLI::Range(1, 10000));
  cmd->add_option("--occlude", o->run.occlude_from,
                  "Hide the gripper from this frame on ... (a lost target)");
  cmd->add_option("--occlude-to", o->run.occlude_to, "... to this frame (exclusive)");
  cmd->add_option("--sensor-px", o->sensor_px, "Square sensor of this many pixels (default: 1280x1024)")
      ->check(CLI::Range(64, 4096));
  add_output_options(*cmd, o->common);
  cmd->callback([o] { run_servo(*o); });
}

}  // namespace mc::cli
