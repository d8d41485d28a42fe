#include "microcobot/studies/control_figures.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <vector>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/motion/closed_loop.h"
#include "microcobot/motion/path_generator.h"
#include "microcobot/motion/setpoint_stream.h"
#include "microcobot/motion/xyz_stage.h"
#include "microcobot/studies/tracking_run.h"

namespace mc::studies {
namespace {

namespace ss = mc::stickslip;
using motion::ControlParams;
using report::Report;
using report::Series;
using Plant = ControlPlant;

// At most `max_points` points of a curve (plots stay light), scaled by `scale`.
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

nlohmann::json velocity_json(const motion::VelocityMetrics& m) {
  return {{"mean_velocity_m_s", m.mean_velocity_m_s},
          {"steady_state_error_rel", m.steady_state_error_rel},
          {"settling_time_s", m.settling_time_s},
          {"settled", m.settled},
          {"excursions", m.excursions},
          {"max_excursion_rel", m.max_excursion_rel},
          {"ripple_m_s", m.ripple_m_s}};
}

nlohmann::json position_json(const motion::PositionMetrics& m) {
  return {{"final_error_m", m.final_error_m}, {"overshoot_m", m.overshoot_m}, {"move_time_s", m.move_time_s}};
}

nlohmann::json tracking_json(const TrackingMetrics& m) {
  return {{"rms_error_m", m.rms_error_m},     {"max_error_m", m.max_error_m},   {"lag_s", m.lag_s},
          {"final_error_m", m.final_error_m}, {"rms_error_all_m", m.rms_all_m}, {"steps", m.edges}};
}

nlohmann::json path_json(const PathMetrics& m) {
  return {{"rms_error_m", m.rms_error_m},          {"max_error_m", m.max_error_m},
          {"path_deviation_m", m.max_deviation_m}, {"path_deviation_rms_m", m.rms_deviation_m},
          {"final_error_m", m.final_error_m},      {"steps", m.edges}};
}

constexpr std::array<TrackerKind, 3> kTrackers{TrackerKind::kTracking, TrackerKind::kHybrid,
                                               TrackerKind::kThesisPid};

std::string json_name(TrackerKind k) { return k == TrackerKind::kThesisPid ? "thesis_pid" : to_string(k); }

/// 3-D line and arc: the three axes on the path, the tracker and both baselines.
nlohmann::json path_experiment(const ControlParams& p, const Plant& plant, const TrajectoryCase& o, Report& r,
                               CsvTable* table) {
  motion::PathLimits lim = p.path;
  lim.max_velocity_m_s = p.limits.max_velocity_m_s;
  lim.max_acceleration_m_s2 = p.limits.max_acceleration_m_s2;
  if (o.jerk > 0.0) lim.max_jerk_m_s3 = o.jerk;
  const Eigen::Vector3d dir = Eigen::Vector3d(0.6, 0.64, 0.48).normalized();
  const auto path =
      o.profile == "line"
          ? motion::PathGenerator::line(-0.5 * o.distance * dir, 0.5 * o.distance * dir, lim)
          : motion::PathGenerator::arc(Eigen::Vector3d(o.radius, 0.0, 0.0), Eigen::Vector3d::Zero(),
                                       Eigen::Vector3d(0.0, 0.3, 1.0), o.angle, lim);
  require_budget(
      3.0 * (path.duration_s() + 0.03) / plant.model.dt_s(), kMaxSimulatedSteps,
      "--distance/--velocity/--acceleration (path duration)",
      fmt::format("simulated steps (3 axes, {:.3g} s at {:g} s)", path.duration_s(), plant.model.dt_s()));
  const auto su = tracker_setup(p);
  nlohmann::json j;
  std::vector<Series> dev;
  for (auto k : kTrackers) {
    const auto run = run_path(plant.model, plant.map, k, su, path);
    const auto name = to_string(k);
    if (k == TrackerKind::kTracking) {
      j = path_json(run.metrics);
      if (table) {
        table->add_column("t_s", run.t_s);
        table->add_column("deviation_m", run.deviation_m);
        for (std::size_t i = 0; i < 3; ++i) {
          const std::string ax = to_string(static_cast<motion::Axis>(i));
          table->add_column("ref_" + ax + "_m", run.ref_m[i]);
          table->add_column(ax + "_m", run.x_m[i]);
        }
      }
    } else {
      j["baseline"][json_name(k)] = path_json(run.metrics);
    }
    r.add_result(name + ": path deviation (max)", run.metrics.max_deviation_m, "m");
    r.add_result(name + ": path deviation (RMS)", run.metrics.rms_deviation_m, "m");
    r.add_result(name + ": final error", run.metrics.final_error_m, "m");
    dev.push_back(thin(name, run.t_s, run.deviation_m));
  }
  r.add_figure(
      {"Path deviation: " + o.profile,
       fmt::format("Distance of the true 3-D position to the ideal {} (length {:.4g} m, <= {:g} m/s, "
                   "<= {:g} m/s^2, <= {:g} m/s^3).",
                   o.profile, path.length_m(), path.path_velocity_m_s(), lim.max_acceleration_m_s2,
                   lim.max_jerk_m_s3),
       {"Time", "s"},
       {"Deviation", "m"},
       dev});
  j["profile"] = o.profile;
  j["length_m"] = path.length_m();
  j["duration_s"] = path.duration_s();
  return j;
}

}  // namespace

nlohmann::json velocity_experiment(const ControlParams& p, const Plant& plant, double speed,
                                   ss::Direction dir, double duration, Report& r, CsvTable* table) {
  const double ref = dir == ss::Direction::kForward ? speed : -speed;
  nlohmann::json j;
  std::vector<Series> v_series, a_series;
  for (auto mode : {motion::VelocityMode::kModelBased, motion::VelocityMode::kThesisPid,
                    motion::VelocityMode::kOpenLoop}) {
    const auto run = motion::run_velocity(plant.model, &plant.map, p.velocity, mode, ref, duration, p.sensor);
    const auto name = to_string(mode);
    if (mode == motion::VelocityMode::kModelBased) {
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
    if (table && mode == motion::VelocityMode::kModelBased) {
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

nlohmann::json position_experiment(const ControlParams& p, const Plant& plant, motion::Axis axis,
                                   double start, double target, Report& r, CsvTable* table) {
  auto sensor = p.sensor;
  sensor.seed += static_cast<int>(axis);  // the XYZ stage's per-axis noise stream
  const auto run = motion::run_position(plant.model, plant.map, p.position, sensor, start, target);
  auto j = position_json(run.metrics);
  j["axis"] = to_string(axis);
  j["in_position"] = run.metrics.in_position;
  j["end_stop"] = run.metrics.end_stop;
  j["hold_peak_to_peak_m"] = run.metrics.hold_pp_m;
  j["switches"] = run.metrics.switches;
  const double duration = run.t_s.empty() ? 0.01 : run.t_s.back();
  std::vector<Series> xs{thin("hybrid", run.t_s, run.x_m)};
  for (auto kind : {motion::BaselineKind::kOpenLoopCounting, motion::BaselineKind::kThesisPid}) {
    const auto b =
        motion::run_baseline_position(plant.model, p.baseline, kind, sensor, start, target, duration);
    const auto name = to_string(kind);
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

nlohmann::json trajectory_experiment(const ControlParams& p0, const Plant& plant, const TrajectoryCase& o,
                                     Report& r, CsvTable* table) {
  auto p = p0;
  if (o.velocity > 0.0) p.limits.max_velocity_m_s = o.velocity;
  if (o.acceleration > 0.0) p.limits.max_acceleration_m_s2 = o.acceleration;
  p.limits.validate();
  if (o.profile == "line" || o.profile == "arc") return path_experiment(p, plant, o, r, table);
  const double sign = o.direction == "backward" ? -1.0 : 1.0;
  const double start = o.profile == "trapezoid" ? -0.5 * sign * o.distance : 0.0;
  // A fresh (stateful) reference per run: every tracker sees the same one.
  std::function<ReferenceFn()> make_ref;
  double duration = 0.0;
  std::string what;
  if (o.profile == "trapezoid") {
    const double end = start + sign * o.distance;
    const auto lim = p.limits;
    make_ref = [lim, start, end] {
      auto l = std::make_shared<motion::ReferenceLimiter>(lim, start);
      return ReferenceFn([l, end](double, double dt) { return l->step(end, dt); });
    };
    duration = motion::trapezoid_duration_s(o.distance, p.limits) + 0.05;
    what = fmt::format("trapezoidal move of {:g} m {} at <= {:g} m/s, <= {:g} m/s^2", o.distance, o.direction,
                       p.limits.max_velocity_m_s, p.limits.max_acceleration_m_s2);
  } else if (o.profile == "sine") {
    auto sine = std::make_shared<motion::SineReference>(start, sign * o.amplitude, o.frequency, p.limits);
    make_ref = [sine] { return ReferenceFn([sine](double t, double) { return sine->at(t); }); };
    duration = 2.0 / o.frequency;
    what = fmt::format("sine of {:g} m amplitude at {:g} Hz", o.amplitude, o.frequency);
  } else {
    // Setpoints streamed at 1 kHz (a staircase of 5 setpoints 10 um apart, 40 ms each, plus a
    // 7 Hz wobble), none between 100 and 110 ms (a dropout: the stream holds, then rejoins
    // under the limits), read through the setpoint stream's bounded look-ahead.
    const auto sp = p.stream;
    const auto lim = p.limits;
    make_ref = [sp, lim, start, sign] {
      auto sps = sp;
      sps.max_velocity_m_s = 1.5 * lim.max_velocity_m_s;  // rejoins after a dropout
      auto stream = std::make_shared<motion::SetpointStream>(sps, start);
      auto next_ms = std::make_shared<double>(0.0);
      return ReferenceFn([stream, next_ms, start, sign](double t, double dt) {
        while (t >= *next_ms) {  // a new setpoint every 1 ms (sender's clock)
          const double ts = *next_ms;
          const int stair = static_cast<int>(ts / 0.04);
          const bool dropout = ts >= 0.1 && ts < 0.11;
          if (!dropout) {
            stream->push(
                ts, start + sign * (10e-6 * std::min(stair, 4) + 0.5e-6 * std::sin(2.0 * M_PI * 7.0 * ts)));
          }
          *next_ms += 1e-3;
        }
        return stream->sample(t, dt);
      });
    };
    duration = 0.25;
    what =
        "setpoints streamed at 1 kHz (staircase 4 x 10 um plus a 7 Hz wobble, a 10 ms dropout), "
        "interpolated with a bounded look-ahead, limited";
  }
  // The work budget, before the runs: a slow trapezoid (tiny velocity or acceleration limit)
  // would otherwise simulate for days.
  require_budget(duration / plant.model.dt_s(), kMaxSimulatedSteps,
                 o.profile == "trapezoid" ? "--velocity/--acceleration (trapezoid duration)" : "--frequency",
                 fmt::format("simulated steps ({:.3g} s at {:g} s)", duration, plant.model.dt_s()));
  const auto su = tracker_setup(p);
  nlohmann::json j;
  std::vector<Series> xs, errs;
  for (auto k : kTrackers) {
    const auto run = run_tracker(plant.model, plant.map, k, su, start, make_ref(), duration);
    const auto name = to_string(k);
    if (k == TrackerKind::kTracking) {
      j = tracking_json(run.metrics);
      xs.push_back(thin("reference", run.t_s, run.ref_m));
      if (table) {
        table->add_column("t_s", run.t_s);
        table->add_column("ref_m", run.ref_m);
        table->add_column("x_m", run.x_m);
        table->add_column("u_V", run.u_V);
      }
    } else {
      j["baseline"][json_name(k)] = tracking_json(run.metrics);
    }
    r.add_result(o.profile + ", " + name + ": RMS tracking error in motion", run.metrics.rms_error_m, "m");
    r.add_result(o.profile + ", " + name + ": max tracking error in motion", run.metrics.max_error_m, "m");
    r.add_result(o.profile + ", " + name + ": lag", run.metrics.lag_s, "s");
    r.add_result(o.profile + ", " + name + ": final error", run.metrics.final_error_m, "m");
    std::vector<double> err(run.x_m.size());
    for (std::size_t i = 0; i < err.size(); ++i) err[i] = run.x_m[i] - run.ref_m[i];
    xs.push_back(thin(name, run.t_s, run.x_m));
    errs.push_back(thin(name, run.t_s, err));
  }
  r.add_figure({"Tracking: " + o.profile, what, {"Time", "s"}, {"Position", "m"}, xs});
  r.add_figure({"Tracking error: " + o.profile,
                "x - reference (true position): the tracking controller (reference-phased sawtooth) and the "
                "baselines (the hybrid position controller fed the moving target, the thesis's PID).",
                {"Time", "s"},
                {"Error", "m"},
                errs});
  j["profile"] = o.profile;
  j["direction"] = o.direction;
  return j;
}

void control_figures(Report& r) {
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
  position_experiment(p, plant, motion::Axis::kX, -100e-6, 100e-6, r, nullptr);
  position_experiment(p, plant, motion::Axis::kX, 100e-6, 100e-6 - 10e-9, r, nullptr);
  r.section("Control: trajectory tracking",
            "microcobot control trajectory --profile trapezoid|sine|stream|arc: the tracking controller "
            "(reference-phased sawtooth) beside the hybrid position controller and the thesis's PID.");
  for (const char* prof : {"trapezoid", "sine", "stream", "arc"}) {
    TrajectoryCase o;
    o.profile = prof;
    trajectory_experiment(p, plant, o, r, nullptr);
  }
}

}  // namespace mc::studies
