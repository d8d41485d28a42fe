// `microcobot control ...`: stick-slip motion control on the model: velocity control of
// thesis §2.7 (Fig. 2.18-2.19), hybrid closed-loop positioning, trajectory tracking, each with its
// baselines (open-loop step counting, the thesis's PID) measured in the same run.

#include <array>
#include <cmath>
#include <memory>

#include <fmt/format.h>

#include "cli.h"
#include "control_learn.h"
#include "control_validate.h"
#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/core/params.h"
#include "microcobot/motion/closed_loop.h"
#include "microcobot/motion/control_params.h"
#include "microcobot/motion/setpoint_stream.h"
#include "microcobot/motion/xyz_stage.h"
#include "microcobot/studies/control_figures.h"
#include "microcobot/studies/tracking_run.h"

namespace control_commands {
namespace {

namespace ss = mc::stickslip;
using mc::cli::CommonOptions;
using mc::report::Figure;
using mc::report::Report;
using mc::report::Series;

using mc::motion::ControlParams;
using Plant = mc::studies::ControlPlant;
using mc::studies::position_experiment;
using mc::studies::trajectory_experiment;
using mc::studies::velocity_experiment;

ControlParams load(const CommonOptions& o) {
  return o.params ? mc::load_params<ControlParams>(*o.params) : ControlParams{};
}

/// The model and its step map (the step map is the expensive part: ~0.3 s).
// ---- velocity ------------------------------------------------------------------------------

struct VelocityOptions {
  CommonOptions common;
  double reference = 100e-6;
  std::string direction = "forward";
  double duration = 0.5;
};

/// The three controllers on one reference; returns the model-based one's summary.
void run_velocity_cmd(const VelocityOptions& o) {
  const auto p = load(o.common);
  const Plant plant(p);
  Report r("control velocity");
  r.section("Velocity control (thesis §2.7)",
            fmt::format("microcobot control velocity --reference {:g} --direction {} "
                        "--duration {:g}",
                        o.reference, o.direction, o.duration));
  mc::CsvTable t;
  auto j = velocity_experiment(p, plant, o.reference, ss::parse_direction(o.direction), o.duration, r, &t);
  mc::cli::write_result_table(o.common, "velocity.csv", t, j);
  mc::cli::write_report_if_requested(o.common, r);
  mc::cli::emit(
      o.common, j,
      fmt::format(
          "mean velocity {:.6g} m/s, steady-state error {:.3f} %, settling {:.4f} s, ripple {:.3g} m/s",
          j["mean_velocity_m_s"].get<double>(), 100.0 * j["steady_state_error_rel"].get<double>(),
          j["settling_time_s"].get<double>(), j["ripple_m_s"].get<double>()));
}

// ---- position ------------------------------------------------------------------------------

struct PositionOptions {
  CommonOptions common;
  double target = 0.0;
  double start = 0.0;
  std::string axis = "x";
};

void run_position_cmd(const PositionOptions& o) {
  const auto p = load(o.common);
  const Plant plant(p);
  Report r("control position");
  r.section("Hybrid position control",
            fmt::format("microcobot control position --target {:g} --start {:g} --axis {}", o.target, o.start,
                        o.axis));
  mc::CsvTable t;
  auto j = position_experiment(p, plant, mc::motion::parse_axis(o.axis), o.start, o.target, r, &t);
  mc::cli::write_result_table(o.common, "position.csv", t, j);
  mc::cli::write_report_if_requested(o.common, r);
  mc::cli::emit(o.common, j,
                fmt::format("final error {:.3g} m, overshoot {:.3g} m, move time {:.4g} s",
                            j["final_error_m"].get<double>(), j["overshoot_m"].get<double>(),
                            j["move_time_s"].get<double>()));
}

// ---- trajectory ----------------------------------------------------------------------------

struct TrajectoryOptions : mc::studies::TrajectoryCase {
  CommonOptions common;
};

void run_trajectory_cmd(const TrajectoryOptions& o) {
  const auto p = load(o.common);
  const double half = 0.5 * p.model.slider.stroke_m;
  if ((o.profile == "trapezoid" || o.profile == "line") && o.distance > 2.0 * half) {
    throw mc::UsageError(fmt::format("--distance must be <= the stroke ({:g} m)", 2.0 * half));
  }
  if (o.profile == "sine" && o.amplitude > half) {
    throw mc::UsageError(fmt::format("--amplitude must be <= half the stroke ({:g} m)", half));
  }
  if (o.profile == "arc" && o.radius > half) {
    throw mc::UsageError(fmt::format("--radius must be <= half the stroke ({:g} m)", half));
  }
  const Plant plant(p);
  Report r("control trajectory");
  r.section("Trajectory tracking", "microcobot control trajectory --profile " + o.profile);
  mc::CsvTable t;
  auto j = trajectory_experiment(p, plant, o, r, &t);
  mc::cli::write_result_table(o.common, "trajectory.csv", t, j);
  mc::cli::write_report_if_requested(o.common, r);
  std::string line = fmt::format("RMS error {:.3g} m, max error {:.3g} m", j["rms_error_m"].get<double>(),
                                 j["max_error_m"].get<double>());
  if (j.contains("lag_s")) line += fmt::format(", lag {:.3g} s", j["lag_s"].get<double>());
  if (j.contains("path_deviation_m")) {
    line += fmt::format(", path deviation {:.3g} m", j["path_deviation_m"].get<double>());
  }
  line += fmt::format(" (baselines: hybrid RMS {:.3g} m, thesis PID RMS {:.3g} m)",
                      j["baseline"]["hybrid"]["rms_error_m"].get<double>(),
                      j["baseline"]["thesis_pid"]["rms_error_m"].get<double>());
  mc::cli::emit(o.common, j, line);
}

void add_control(CLI::App& group) {
  {
    auto o = std::make_shared<CommonOptions>();
    auto* cmd = group.add_subcommand("params", "Print every control parameter (the --params keys)");
    mc::cli::add_output_options(*cmd, *o);
    mc::cli::add_params_option(*cmd, *o);
    cmd->callback([o] { mc::cli::emit(*o, mc::params_to_json(load(*o)), mc::params_to_yaml(load(*o))); });
  }
  {
    auto o = std::make_shared<VelocityOptions>();
    auto* cmd =
        group.add_subcommand("velocity", "Velocity control (thesis §2.7, Fig. 2.18-2.19) with baselines");
    cmd->add_option("--reference", o->reference, "Reference speed [m/s]")->check(mc::cli::Range(1e-7, 1e-2));
    cmd->add_option("--direction", o->direction, "forward | backward")
        ->check(CLI::IsMember({"forward", "backward"}));
    cmd->add_option("--duration", o->duration, "Simulated time [s]")->check(mc::cli::Range(0.02, 100.0));
    mc::cli::add_output_options(*cmd, o->common);
    mc::cli::add_format_option(*cmd, o->common);
    mc::cli::add_params_option(*cmd, o->common);
    cmd->callback([o] { run_velocity_cmd(*o); });
  }
  {
    auto o = std::make_shared<PositionOptions>();
    auto* cmd =
        group.add_subcommand("position", "Hybrid stepping/scanning move of one XYZ axis, with baselines");
    cmd->add_option("--target", o->target, "Target position [m] (stroke +-6 mm)")
        ->required()
        ->check(mc::cli::Range(-6.5e-3, 6.5e-3));
    cmd->add_option("--start", o->start, "Start position [m]")->check(mc::cli::Range(-6e-3, 6e-3));
    cmd->add_option("--axis", o->axis, "x | y | z")->check(CLI::IsMember({"x", "y", "z"}));
    mc::cli::add_output_options(*cmd, o->common);
    mc::cli::add_format_option(*cmd, o->common);
    mc::cli::add_params_option(*cmd, o->common);
    cmd->callback([o] { run_position_cmd(*o); });
  }
  {
    auto o = std::make_shared<TrajectoryOptions>();
    auto* cmd = group.add_subcommand(
        "trajectory",
        "Trajectory tracking (trapezoid, sine, streamed setpoints, 3-D line and arc) with baselines");
    cmd->add_option("--profile", o->profile, "trapezoid | sine | stream | line | arc")
        ->check(CLI::IsMember({"trapezoid", "sine", "stream", "line", "arc"}));
    cmd->add_option("--direction", o->direction, "forward | backward (1-D profiles)")
        ->check(CLI::IsMember({"forward", "backward"}));
    cmd->add_option("--distance", o->distance, "Trapezoid / line: distance [m]")
        ->check(mc::cli::Range(1e-9, 12e-3));
    cmd->add_option("--velocity", o->velocity, "Velocity limit [m/s]")->check(mc::cli::Range(1e-7, 1e-2));
    cmd->add_option("--acceleration", o->acceleration, "Acceleration limit [m/s^2]")
        ->check(mc::cli::Range(1e-6, 10.0));
    cmd->add_option("--jerk", o->jerk, "Line / arc: jerk limit [m/s^3]")->check(mc::cli::Range(1e-6, 1e6));
    cmd->add_option("--amplitude", o->amplitude, "Sine: amplitude [m]")->check(mc::cli::Range(1e-9, 6e-3));
    cmd->add_option("--frequency", o->frequency, "Sine: frequency [Hz]")->check(mc::cli::Range(1e-3, 100.0));
    cmd->add_option("--radius", o->radius, "Arc: radius [m]")->check(mc::cli::Range(1e-7, 6e-3));
    cmd->add_option("--angle", o->angle, "Arc: angle [rad]")->check(mc::cli::Range(-2.0 * M_PI, 2.0 * M_PI));
    mc::cli::add_output_options(*cmd, o->common);
    mc::cli::add_format_option(*cmd, o->common);
    mc::cli::add_params_option(*cmd, o->common);
    cmd->callback([o] { run_trajectory_cmd(*o); });
  }
  mc::cli::add_control_validate(group);
  mc::cli::add_control_learn(group);
}

const bool kRegistered = mc::cli::register_group(
    {"control", "Stick-slip motion control (thesis §2.7): params, velocity, position, trajectory", 50,
     &add_control});

}  // namespace
}  // namespace control_commands
