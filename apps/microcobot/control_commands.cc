// `microcobot control ...`: stick-slip motion control on the model (#6): velocity control of
// thesis §2.7 (Fig. 2.18-2.19), hybrid closed-loop positioning, trajectory tracking, each with its
// baselines (open-loop step counting, the thesis's PID) measured in the same run.

#include <cmath>
#include <memory>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/control/closed_loop.h"
#include "microcobot/control/control_params.h"
#include "microcobot/control/xyz_stage.h"
#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/core/params.h"

namespace {

namespace ct = mc::control;
namespace ss = mc::stickslip;
using mc::cli::CommonOptions;
using mc::report::Figure;
using mc::report::Report;
using mc::report::Series;

using ct::ControlParams;

ControlParams load(const CommonOptions& o) {
  return o.params ? mc::load_params<ControlParams>(*o.params) : ControlParams{};
}

/// The model and its step map (the step map is the expensive part: ~0.3 s).
struct Plant {
  ss::ActuatorModel model;
  ct::StepMap map;
  explicit Plant(const ControlParams& p) : model(p.model), map(model, p.step_map) {}
};

Series thin(const std::string& name, const std::vector<double>& x, const std::vector<double>& y,
            std::size_t max_points = 4000, double scale = 1.0) {
  Series s{name, {}, {}, false};
  const std::size_t every = std::max<std::size_t>(1, x.size() / max_points);
  for (std::size_t i = 0; i < x.size(); i += every) {
    s.x.push_back(x[i]);
    s.y.push_back(y[i] * scale);
  }
  return s;
}

void write_table(const CommonOptions& o, const std::string& file, const mc::CsvTable& t) {
  if (!o.out) return;
  mc::ensure_writable_dir(*o.out);
  mc::write_csv(*o.out / file, t);
}

nlohmann::json velocity_json(const ct::VelocityMetrics& m) {
  return {{"mean_velocity_m_s", m.mean_velocity_m_s},
          {"steady_state_error_rel", m.steady_state_error_rel},
          {"settling_time_s", m.settling_time_s},
          {"settled", m.settled},
          {"excursions", m.excursions},
          {"max_excursion_rel", m.max_excursion_rel},
          {"ripple_m_s", m.ripple_m_s}};
}

nlohmann::json position_json(const ct::PositionMetrics& m) {
  return {{"final_error_m", m.final_error_m}, {"overshoot_m", m.overshoot_m}, {"move_time_s", m.move_time_s}};
}

// ---- velocity ------------------------------------------------------------------------------

struct VelocityOptions {
  CommonOptions common;
  double reference = 100e-6;
  std::string direction = "forward";
  double duration = 0.5;
};

/// The three controllers on one reference; returns the model-based one's summary.
nlohmann::json velocity_experiment(const ControlParams& p, const Plant& plant, double speed,
                                   ss::Direction dir, double duration, Report& r, mc::CsvTable* table) {
  const double ref = dir == ss::Direction::kForward ? speed : -speed;
  nlohmann::json j;
  std::vector<Series> v_series, a_series;
  for (auto mode :
       {ct::VelocityMode::kModelBased, ct::VelocityMode::kThesisPid, ct::VelocityMode::kOpenLoop}) {
    const auto run = ct::run_velocity(plant.model, &plant.map, p.velocity, mode, ref, duration, p.sensor);
    const auto name = ct::to_string(mode);
    if (mode == ct::VelocityMode::kModelBased) {
      j = velocity_json(run.metrics);
    } else {
      j["baselines"][name] = velocity_json(run.metrics);
    }
    r.add_result(name + ": steady-state error", run.metrics.steady_state_error_rel * 100.0, "%");
    r.add_result(name + ": settling time", run.metrics.settling_time_s, "s");
    r.add_result(name + ": ripple", run.metrics.ripple_m_s, "m/s");
    r.add_result(name + ": largest excursion after settling (5-period mean)",
                 run.metrics.max_excursion_rel * 100.0, "%");
    v_series.push_back(thin(name + " (1-period velocity)", run.t_s, run.v_true_m_s));
    a_series.push_back(thin(name, run.t_s, run.amplitude_V));
    if (table && mode == ct::VelocityMode::kModelBased) {
      table->add_column("t_s", run.t_s);
      table->add_column("v_m_s", run.v_true_m_s);
      table->add_column("v_est_m_s", run.v_est_m_s);
      table->add_column("amplitude_V", run.amplitude_V);
    }
  }
  const double t_end = v_series.front().x.empty() ? duration : v_series.front().x.back();
  v_series.push_back(Series{"reference", {0.0, t_end}, {ref, ref}, false});
  const auto d = ss::to_string(dir);
  r.add_figure({"Velocity control " + d + " (Fig. 2.19)",
                fmt::format("1 kHz sawtooth, PID on the amplitude, velocity from positions {} periods apart; "
                            "reference {:g} m/s. Model-based = PID + step-map feedforward.",
                            p.velocity.delay_periods, ref),
                {"Time", "s"},
                {"Velocity", "m/s"},
                v_series});
  r.add_figure({"Sawtooth amplitude " + d,
                "The amplitude each controller commands.",
                {"Time", "s"},
                {"Amplitude", "V"},
                a_series});
  return j;
}

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
  write_table(o.common, "velocity.csv", t);
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

nlohmann::json position_experiment(const ControlParams& p, const Plant& plant, ct::Axis axis, double start,
                                   double target, Report& r, mc::CsvTable* table) {
  auto sensor = p.sensor;
  sensor.seed += static_cast<int>(axis);  // the XYZ stage's per-axis noise stream
  const auto run = ct::run_position(plant.model, plant.map, p.position, sensor, start, target);
  auto j = position_json(run.metrics);
  j["axis"] = ct::to_string(axis);
  j["in_position"] = run.metrics.in_position;
  j["end_stop"] = run.metrics.end_stop;
  j["hold_peak_to_peak_m"] = run.metrics.hold_pp_m;
  j["switches"] = run.metrics.switches;
  const double duration = run.t_s.empty() ? 0.01 : run.t_s.back();
  std::vector<Series> xs{thin("hybrid", run.t_s, run.x_m)};
  for (auto kind : {ct::BaselineKind::kOpenLoopCounting, ct::BaselineKind::kThesisPid}) {
    const auto b = ct::run_baseline_position(plant.model, p.baseline, kind, sensor, start, target, duration);
    const auto name = ct::to_string(kind);
    j["baselines"][name] = position_json(b.metrics);
    r.add_result(name + ": final error", b.metrics.final_error_m, "m");
    r.add_result(name + ": overshoot", b.metrics.overshoot_m, "m");
    xs.push_back(thin(name, b.t_s, b.x_m));
  }
  r.add_result("hybrid: final error", run.metrics.final_error_m, "m");
  r.add_result("hybrid: overshoot", run.metrics.overshoot_m, "m");
  r.add_result("hybrid: move time", run.metrics.move_time_s, "s");
  r.add_result("hybrid: hold peak-to-peak", run.metrics.hold_pp_m, "m");
  xs.push_back(Series{"target", {0.0, duration}, {target, target}, false});
  const auto title = fmt::format("Move {:g} m -> {:g} m", start, target);
  r.add_figure({title,
                "True slider position of the hybrid controller and the baselines (same sensor noise).",
                {"Time", "s"},
                {"Position", "m"},
                xs});
  std::vector<double> err(run.x_m.size());
  for (std::size_t i = 0; i < err.size(); ++i) err[i] = run.x_m[i] - target;
  r.add_figure({title + ": switching",
                "Error, drive voltage / 100 and mode (1 stepping, 2 raise, 3 scanning, 4 hold).",
                {"Time", "s"},
                {"Value", ""},
                {thin("error [um]", run.t_s, err, 4000, 1e6), thin("U / 100 V", run.t_s, run.u_V, 4000, 0.01),
                 thin("mode", run.t_s, run.mode)}});
  if (table) {
    table->add_column("t_s", run.t_s);
    table->add_column("x_m", run.x_m);
    table->add_column("u_V", run.u_V);
    table->add_column("mode", run.mode);
  }
  return j;
}

void run_position_cmd(const PositionOptions& o) {
  const auto p = load(o.common);
  const Plant plant(p);
  Report r("control position");
  r.section("Hybrid position control",
            fmt::format("microcobot control position --target {:g} --start {:g} --axis {}", o.target, o.start,
                        o.axis));
  mc::CsvTable t;
  auto j = position_experiment(p, plant, ct::parse_axis(o.axis), o.start, o.target, r, &t);
  write_table(o.common, "position.csv", t);
  mc::cli::write_report_if_requested(o.common, r);
  mc::cli::emit(o.common, j,
                fmt::format("final error {:.3g} m, overshoot {:.3g} m, move time {:.4g} s",
                            j["final_error_m"].get<double>(), j["overshoot_m"].get<double>(),
                            j["move_time_s"].get<double>()));
}

// ---- trajectory ----------------------------------------------------------------------------

struct TrajectoryOptions {
  CommonOptions common;
  std::string profile = "trapezoid";
  double distance = 100e-6;
  double velocity = 0.0;      // 0: limits.max_velocity_m_s
  double acceleration = 0.0;  // 0: limits.max_acceleration_m_s2
  double amplitude = 20e-6;
  double frequency = 1.0;
};

nlohmann::json trajectory_experiment(const ControlParams& p0, const Plant& plant, const TrajectoryOptions& o,
                                     Report& r, mc::CsvTable* table) {
  auto p = p0;
  if (o.velocity > 0.0) p.limits.max_velocity_m_s = o.velocity;
  if (o.acceleration > 0.0) p.limits.max_acceleration_m_s2 = o.acceleration;
  p.limits.validate();
  // The scanning reference must keep up with the trajectory.
  p.position.scan_velocity_m_s = std::max(p.position.scan_velocity_m_s, 1.5 * p.limits.max_velocity_m_s);
  p.position.scan_acceleration_m_s2 =
      std::max(p.position.scan_acceleration_m_s2, 1.5 * p.limits.max_acceleration_m_s2);
  const double start = o.profile == "trapezoid" ? -0.5 * o.distance : 0.0;
  std::function<ct::ReferenceSample(double, double)> ref;
  double duration = 0.0;
  std::string what;
  if (o.profile == "trapezoid") {
    auto lim = std::make_shared<ct::ReferenceLimiter>(p.limits, start);
    const double end = start + o.distance;
    ref = [lim, end](double, double dt) { return lim->step(end, dt); };
    duration = ct::trapezoid_duration_s(o.distance, p.limits) + 0.05;
    what = fmt::format("trapezoidal move of {:g} m at <= {:g} m/s, <= {:g} m/s^2", o.distance,
                       p.limits.max_velocity_m_s, p.limits.max_acceleration_m_s2);
  } else if (o.profile == "sine") {
    auto sine = std::make_shared<ct::SineReference>(start, o.amplitude, o.frequency, p.limits);
    ref = [sine](double t, double) { return sine->at(t); };
    duration = 2.0 / o.frequency;
    what = fmt::format("sine of {:g} m amplitude at {:g} Hz", o.amplitude, o.frequency);
  } else {
    // A setpoint sequence streamed at 1 kHz: a staircase of 5 setpoints (10 um apart, 40 ms each)
    // with sensor-like jitter, smoothed by the limiter.
    auto lim = std::make_shared<ct::ReferenceLimiter>(p.limits, start);
    auto held = std::make_shared<double>(start);
    auto next_ms = std::make_shared<double>(0.0);
    ref = [lim, held, next_ms, start](double t, double dt) {
      if (t >= *next_ms) {  // a new setpoint arrives every 1 ms
        const int stair = static_cast<int>(t / 0.04);
        *held = start + 10e-6 * std::min(stair, 4) + 0.5e-6 * std::sin(2.0 * M_PI * 7.0 * t);
        *next_ms += 1e-3;
      }
      return lim->step(*held, dt);
    };
    duration = 0.25;
    what = "setpoints streamed at 1 kHz (staircase 4 x 10 um plus a 7 Hz wobble), limited";
  }
  // The work budget, before the run: a slow trapezoid (tiny velocity or acceleration limit)
  // would otherwise simulate for days.
  mc::require_budget(
      duration / plant.model.dt_s(), mc::kMaxSimulatedSteps,
      o.profile == "trapezoid" ? "--velocity/--acceleration (trapezoid duration)" : "--frequency",
      fmt::format("simulated steps ({:.3g} s at {:g} s)", duration, plant.model.dt_s()));
  const auto run = ct::run_tracking(plant.model, plant.map, p.position, p.sensor, start, ref, duration);
  r.add_result(o.profile + ": RMS tracking error", run.rms_error_m, "m");
  r.add_result(o.profile + ": max tracking error", run.max_error_m, "m");
  std::vector<double> err(run.x_m.size());
  for (std::size_t i = 0; i < err.size(); ++i) err[i] = run.x_m[i] - run.ref_m[i];
  r.add_figure({"Tracking: " + o.profile,
                what,
                {"Time", "s"},
                {"Position", "m"},
                {thin("reference", run.t_s, run.ref_m), thin("slider", run.t_s, run.x_m)}});
  r.add_figure({"Tracking error: " + o.profile,
                "x - reference (true position).",
                {"Time", "s"},
                {"Error", "m"},
                {thin("error", run.t_s, err)}});
  if (table) {
    table->add_column("t_s", run.t_s);
    table->add_column("ref_m", run.ref_m);
    table->add_column("x_m", run.x_m);
    table->add_column("u_V", run.u_V);
  }
  return {{"rms_error_m", run.rms_error_m}, {"max_error_m", run.max_error_m}, {"profile", o.profile}};
}

void run_trajectory_cmd(const TrajectoryOptions& o) {
  const auto p = load(o.common);
  const double half = 0.5 * p.model.slider.stroke_m;
  if (o.profile == "trapezoid" && o.distance > 2.0 * half) {
    throw mc::UsageError(fmt::format("--distance must be <= the stroke ({:g} m)", 2.0 * half));
  }
  if (o.profile == "sine" && o.amplitude > half) {
    throw mc::UsageError(fmt::format("--amplitude must be <= half the stroke ({:g} m)", half));
  }
  const Plant plant(p);
  Report r("control trajectory");
  r.section("Trajectory tracking", "microcobot control trajectory --profile " + o.profile);
  mc::CsvTable t;
  auto j = trajectory_experiment(p, plant, o, r, &t);
  write_table(o.common, "trajectory.csv", t);
  mc::cli::write_report_if_requested(o.common, r);
  mc::cli::emit(o.common, j,
                fmt::format("RMS error {:.3g} m, max error {:.3g} m", j["rms_error_m"].get<double>(),
                            j["max_error_m"].get<double>()));
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
    mc::cli::add_params_option(*cmd, o->common);
    cmd->callback([o] { run_position_cmd(*o); });
  }
  {
    auto o = std::make_shared<TrajectoryOptions>();
    auto* cmd = group.add_subcommand("trajectory", "Trajectory tracking under velocity/acceleration limits");
    cmd->add_option("--profile", o->profile, "trapezoid | sine | stream")
        ->check(CLI::IsMember({"trapezoid", "sine", "stream"}));
    cmd->add_option("--distance", o->distance, "Trapezoid: distance [m]")->check(mc::cli::Range(1e-9, 12e-3));
    cmd->add_option("--velocity", o->velocity, "Velocity limit [m/s]")->check(mc::cli::Range(1e-7, 1e-2));
    cmd->add_option("--acceleration", o->acceleration, "Acceleration limit [m/s^2]")
        ->check(mc::cli::Range(1e-6, 10.0));
    cmd->add_option("--amplitude", o->amplitude, "Sine: amplitude [m]")->check(mc::cli::Range(1e-9, 6e-3));
    cmd->add_option("--frequency", o->frequency, "Sine: frequency [Hz]")->check(mc::cli::Range(1e-3, 100.0));
    mc::cli::add_output_options(*cmd, o->common);
    mc::cli::add_params_option(*cmd, o->common);
    cmd->callback([o] { run_trajectory_cmd(*o); });
  }
}

void control_part(Report& r) {
  const ControlParams p;
  const Plant plant(p);
  r.section("Control: velocity (thesis §2.7, Fig. 2.18-2.19)",
            "microcobot control velocity --reference 1e-4 --direction forward|backward --duration 0.3. "
            "Model-based PID (with the step map's feedforward), the thesis's PID alone and open-loop step "
            "counting (a step assumed proportional to the amplitude) on the same model and sensor.");
  velocity_experiment(p, plant, 100e-6, ss::Direction::kForward, 0.3, r, nullptr);
  velocity_experiment(p, plant, 100e-6, ss::Direction::kBackward, 0.3, r, nullptr);
  r.section("Control: hybrid positioning",
            "microcobot control position --start -1e-4 --target 1e-4, and --start 1e-4 --target 9.99e-5 (10 "
            "nm back). "
            "Stepping (amplitude/frequency from the step map) -> scanning with the PI inverse -> hold.");
  position_experiment(p, plant, ct::Axis::kX, -100e-6, 100e-6, r, nullptr);
  position_experiment(p, plant, ct::Axis::kX, 100e-6, 100e-6 - 10e-9, r, nullptr);
  r.section("Control: trajectory tracking", "microcobot control trajectory --profile trapezoid|sine|stream");
  for (const char* prof : {"trapezoid", "sine", "stream"}) {
    TrajectoryOptions o;
    o.profile = prof;
    trajectory_experiment(p, plant, o, r, nullptr);
  }
}

const bool kRegistered = mc::cli::register_group(
    {"control", "Stick-slip motion control (thesis §2.7): params, velocity, position, trajectory", 50,
     &add_control});
const bool kPart = mc::cli::register_report_part({"control", 50, &control_part});

}  // namespace
