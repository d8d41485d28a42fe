// microcobot.control and microcobot.platform: the stick-slip controllers steppable from a Python loop
// and the closed-loop runs of `microcobot control` (motion/closed_loop.h); the platform's scenario
// runs (`microcobot run`) and its recordings (CSV, MCAP, .mat) as dicts of numpy arrays.

#include <map>

#include <nlohmann/json.hpp>

#include "common.h"
#include "microcobot/cell/session.h"
#include "microcobot/core/csv.h"
#include "microcobot/core/mat_file.h"
#include "microcobot/core/mcap_reader.h"
#include "microcobot/haptics/dual_stage_plant.h"
#include "microcobot/haptics/evaluation.h"
#include "microcobot/haptics/identification.h"
#include "microcobot/haptics/render_pipeline.h"
#include "microcobot/motion/closed_loop.h"
#include "microcobot/motion/control_params.h"
#include "microcobot/motion/position_controller.h"
#include "microcobot/motion/position_sensor.h"
#include "microcobot/motion/setpoint_stream.h"
#include "microcobot/motion/step_map.h"
#include "microcobot/motion/velocity_controller.h"
#include "microcobot/platform/platform_config.h"
#include "microcobot/platform/telemetry_schema.h"
#include "microcobot/studies/tracking_run.h"
#include "microcobot/tweezers/ballscrew.h"
#include "microcobot/tweezers/bandwidth.h"
#include "microcobot/tweezers/specs.h"
#include "microcobot/tweezers/transmission.h"

namespace mc::py {

// Shared with cell_py.cc (common.h).
platform::PlatformConfig config_from(py::handle c) {
  if (py::isinstance<py::str>(c) || py::hasattr(c, "__fspath__")) {
    return platform::load_platform_config(
        py::str(py::module_::import("os").attr("fspath")(c)).cast<std::string>());
  }
  return params_from<platform::PlatformConfig>(c);
}

namespace {

namespace pf = mc::platform;

namespace ss = mc::stickslip;
using namespace pybind11::literals;

/// One controlled axis: its parameters, the model and the model's step map (built once: the
/// expensive part, ~0.3 s). Controllers keep a reference to it (kept alive by pybind11).
struct Plant {
  motion::ControlParams params;
  ss::ActuatorModel model;
  motion::StepMap map;
  explicit Plant(const motion::ControlParams& p) : params(p), model(p.model), map(model, p.step_map) {}
};

py::tuple operating_point(const motion::SawtoothGenerator& g) {
  return py::make_tuple(g.amplitude_V(), g.frequency_Hz(), ss::to_string(g.direction()));
}

py::dict velocity_metrics_dict(const motion::VelocityMetrics& m) {
  return py::dict(
      "mean_velocity_m_s"_a = m.mean_velocity_m_s, "steady_state_error_rel"_a = m.steady_state_error_rel,
      "settling_time_s"_a = m.settling_time_s, "settled"_a = m.settled, "ripple_m_s"_a = m.ripple_m_s,
      "excursions"_a = m.excursions, "max_excursion_rel"_a = m.max_excursion_rel);
}

py::dict position_run_dict(const motion::PositionRun& r) {
  const auto& m = r.metrics;
  return py::dict(
      "t_s"_a = to_array(r.t_s), "x_m"_a = to_array(r.x_m), "u_V"_a = to_array(r.u_V),
      "mode"_a = to_array(r.mode),
      "metrics"_a = py::dict("final_error_m"_a = m.final_error_m, "overshoot_m"_a = m.overshoot_m,
                             "move_time_s"_a = m.move_time_s, "in_position"_a = m.in_position,
                             "hold_pp_m"_a = m.hold_pp_m, "hold_voltage_pp_V"_a = m.hold_voltage_pp_V,
                             "stepped_in_hold"_a = m.stepped_in_hold, "switches"_a = m.switches,
                             "end_stop"_a = m.end_stop));
}

py::dict table_dict(const CsvTable& t) {
  py::dict d;
  for (std::size_t i = 0; i < t.cols(); ++i) d[py::str(t.names()[i])] = to_array(t.column(i));
  return d;
}

std::string path_of(py::handle p) {
  return py::str(py::module_::import("os").attr("fspath")(p)).cast<std::string>();
}

/// MCAP file -> {topic: {'log_time_s': array, <numeric JSON field>: array, ..., 'units': {field:
/// unit}}}; messages whose encoding is not JSON keep their count only ('messages'). 'units' holds
/// the fields whose JSON Schema property declares a `unit` (the telemetry's: "" for flags).
py::dict mcap_dict(const McapContents& c) {
  struct Topic {
    std::vector<double> t;
    std::map<std::string, std::vector<double>> fields;
    std::size_t messages = 0;
  };
  std::map<std::string, Topic> topics;
  for (const auto& msg : c.messages) {
    const McapChannel* ch = c.channel(msg.channel_id);
    if (!ch) continue;
    Topic& tp = topics[ch->topic];
    ++tp.messages;
    if (ch->message_encoding != "json") continue;
    const auto j = nlohmann::json::parse(msg.data, nullptr, false);
    if (!j.is_object())
      throw InvalidInput("mcap: message " + std::to_string(msg.sequence) + " on " + ch->topic +
                         " is not a JSON object");
    const std::size_t k = tp.t.size();
    tp.t.push_back(static_cast<double>(msg.log_time_ns) * 1e-9);
    for (const auto& [key, v] : j.items()) {
      if (!v.is_number()) continue;
      auto& col = tp.fields[key];
      col.resize(k, std::numeric_limits<double>::quiet_NaN());  // a field absent from earlier messages
      col.push_back(v.get<double>());
    }
  }
  // The units the channels' JSON Schemas declare, by topic.
  std::map<std::string, py::dict> units;
  for (const auto& ch : c.channels) {
    const McapSchema* schema = c.schema(ch.schema_id);
    if (schema == nullptr || schema->encoding != "jsonschema") continue;
    const auto j = nlohmann::json::parse(schema->data, nullptr, false);
    if (!j.is_object() || !j.contains("properties") || !j["properties"].is_object()) continue;
    py::dict u;
    for (const auto& [key, prop] : j["properties"].items())
      if (prop.is_object() && prop.contains("unit") && prop["unit"].is_string())
        u[py::str(key)] = prop["unit"].get<std::string>();
    if (!u.empty()) units[ch.topic] = u;
  }
  py::dict out;
  for (auto& [name, tp] : topics) {
    py::dict d("messages"_a = tp.messages, "log_time_s"_a = to_array(tp.t));
    if (const auto it = units.find(name); it != units.end()) d["units"] = it->second;
    for (auto& [key, col] : tp.fields) {
      if (col.size() != tp.t.size()) {
        throw InvalidInput("mcap: field '" + key + "' of " + name + " is missing from some messages");
      }
      require_finite_result(col, "mcap field " + key);
      d[py::str(key)] = to_array(col);
    }
    out[py::str(name)] = d;
  }
  return out;
}

py::dict read_mat_dict(const std::string& path) {
  py::dict d;
  for (const auto& a : read_mat(path)) {
    // MATLAB's column-major (rows, cols), as scipy.io.loadmat returns it.
    py::array_t<double, py::array::f_style> arr(
        {static_cast<py::ssize_t>(a.rows), static_cast<py::ssize_t>(a.cols)});
    std::copy(a.data.begin(), a.data.end(), arr.mutable_data());
    d[py::str(a.name)] = arr;
  }
  return d;
}

void write_mat_dict(const std::string& path, const py::dict& vars) {
  std::vector<MatArray> out;
  for (const auto& [k, v] : vars) {
    const auto name = py::str(k).cast<std::string>();
    const auto a = py::cast<py::array_t<double, py::array::f_style | py::array::forcecast>>(v);
    MatArray m;
    m.name = name;
    if (a.ndim() == 0) {
      m.rows = m.cols = 1;
    } else if (a.ndim() == 1) {
      m.rows = static_cast<std::size_t>(a.shape(0));  // a vector is a column, as the CLI writes
      m.cols = 1;
    } else if (a.ndim() == 2) {
      m.rows = static_cast<std::size_t>(a.shape(0));
      m.cols = static_cast<std::size_t>(a.shape(1));
    } else {
      throw InvalidInput(path + ": variable '" + name + "': expected at most 2 dimensions, got " +
                         std::to_string(a.ndim()));
    }
    m.data.assign(a.data(), a.data() + a.size());
    for (std::size_t i = 0; i < m.data.size(); ++i) {
      if (!std::isfinite(m.data[i])) {
        throw InvalidInput(path + ": variable '" + name + "': non-finite value at index " +
                           std::to_string(i));
      }
    }
    out.push_back(std::move(m));
  }
  write_mat(path, out);
}

}  // namespace

void bind_control(py::module_& m) {
  m.def(
      "params", [](py::handle p) { return params_dict(params_from<motion::ControlParams>(p)); },
      "params"_a = py::none(),
      "Every parameter of a controlled axis (model, step_map, sensor, velocity, position, baseline, limits): "
      "the keys "
      "of `microcobot control params --json`.");

  py::class_<Plant>(m, "Plant",
                    "A controlled axis: its parameters, the stick-slip model and its step map (built once, "
                    "~0.3 s).")
      .def(py::init(
               [](py::handle p) { return std::make_unique<Plant>(params_from<motion::ControlParams>(p)); }),
           "params"_a = py::none())
      .def_property_readonly(
          "model", [](const Plant& p) { return p.model; }, "The stick-slip model (an Actuator copy)")
      .def_property_readonly("params", [](const Plant& p) { return params_dict(p.params); })
      .def(
          "steps_per_tick", [](const Plant& p, double rate) { return motion::steps_per_tick(p.model, rate); },
          "control_rate_Hz"_a, "Model steps per control tick (the control period must be whole model steps).")
      .def(
          "step_length",
          [](const Plant& p, double a, double f, const std::string& d) {
            return p.map.step_m(a, f, ss::parse_direction(d));
          },
          "amplitude_V"_a, "frequency_Hz"_a, "direction"_a = "forward",
          "|step| per sawtooth period [m] at (A, f, direction) from the step map (thesis §2.5.3, Fig. "
          "2.15).");

  py::class_<motion::PositionSensor>(m, "PositionSensor",
                                     "Position sensor (thesis §2.3): x + white noise, quantised.")
      .def(py::init([](py::handle p) {
             return motion::PositionSensor(params_from<motion::PositionSensorParams>(p));
           }),
           "params"_a = py::none())
      .def("measure", &motion::PositionSensor::measure, "true_position_m"_a, "Measured position [m]");

  py::class_<motion::VelocityController>(
      m, "VelocityController",
      "Velocity control (thesis §2.7, Fig. 2.18): 1 kHz sawtooth whose amplitude a PID "
      "sets from the velocity error. Call update() at control_rate_Hz and next_drive() "
      "at every model step.")
      .def(py::init([](const Plant& p, const std::string& mode) {
             return motion::VelocityController(p.params.velocity, motion::parse_velocity_mode(mode), &p.map,
                                               p.model.params().drive.slew_rate_V_s);
           }),
           "plant"_a, "mode"_a = "model", py::keep_alive<1, 2>(), "mode: 'model' | 'pid' | 'open-loop'.")
      .def("set_reference", &motion::VelocityController::set_reference, "v_m_s"_a, "Reference velocity [m/s]")
      .def(
          "update",
          [](motion::VelocityController& c, double x) {
            require(std::isfinite(x), "measured_position_m", "must be finite", x);
            c.update(x);
          },
          "measured_position_m"_a, "One control tick with the measured slider position [m].")
      .def("next_drive", &motion::VelocityController::next_drive, "dt_s"_a,
           "The drive over the next model step (pass it to Actuator.step).")
      .def("emergency_stop", &motion::VelocityController::emergency_stop, "0 V at once, integrator cleared.")
      .def_property_readonly("velocity_estimate_m_s", &motion::VelocityController::velocity_estimate_m_s)
      .def_property_readonly("amplitude_V", &motion::VelocityController::amplitude_V)
      .def_property_readonly("end_stop", &motion::VelocityController::end_stop)
      .def_property_readonly(
          "operating_point",
          [](const motion::VelocityController& c) { return operating_point(c.generator()); },
          "(amplitude_V, frequency_Hz, direction) of the sawtooth, for Actuator.set_operating_point (thesis "
          "§2.7).");

  py::class_<motion::PositionController>(
      m, "PositionController",
      "Hybrid positioning: stepping far from the target, scanning with the inverse PI "
      "hysteresis (eq. 2.5) near it, then hold.")
      .def(py::init([](const Plant& p) {
             return std::make_unique<motion::PositionController>(p.params.position, p.params.model, p.map);
           }),
           "plant"_a, py::keep_alive<1, 2>())
      .def(
          "set_target",
          [](motion::PositionController& c, double target, double v) {
            require(std::isfinite(target) && std::isfinite(v), "target_m", "must be finite", target);
            c.set_target(target, v);
          },
          "target_m"_a, "velocity_m_s"_a = 0.0,
          "New target [m] and reference velocity [m/s] (trajectory feedforward; 0 for a move). Clears an end "
          "stop.")
      .def(
          "update",
          [](motion::PositionController& c, double x) {
            require(std::isfinite(x), "measured_position_m", "must be finite", x);
            c.update(x);
          },
          "measured_position_m"_a, "One control tick with the measured slider position [m].")
      .def("next_drive", &motion::PositionController::next_drive, "dt_s"_a,
           "The drive over the next model step (pass it to Actuator.step).")
      .def("emergency_stop", &motion::PositionController::emergency_stop,
           "0 V at once; the axis stays stopped until the next set_target().")
      .def_property_readonly("mode", [](const motion::PositionController& c) { return to_string(c.mode()); })
      .def_property_readonly("in_position", &motion::PositionController::in_position)
      .def_property_readonly("end_stop", &motion::PositionController::end_stop)
      .def_property_readonly("voltage_V", &motion::PositionController::voltage_V)
      .def_property_readonly("operating_point", [](const motion::PositionController& c) {
        return operating_point(c.generator());
      });

  m.def(
      "run_velocity",
      [](const Plant& p, double reference_m_s, const std::string& mode, double duration_s, double start_m) {
        const auto mo = motion::parse_velocity_mode(mode);
        const auto r = nogil([&] {
          return motion::run_velocity(p.model, &p.map, p.params.velocity, mo, reference_m_s, duration_s,
                                      p.params.sensor, start_m);
        });
        return py::dict("t_s"_a = to_array(r.t_s), "v_m_s"_a = to_array(r.v_true_m_s),
                        "v_est_m_s"_a = to_array(r.v_est_m_s), "amplitude_V"_a = to_array(r.amplitude_V),
                        "metrics"_a = velocity_metrics_dict(r.metrics));
      },
      "plant"_a, "reference_m_s"_a, "mode"_a = "model", "duration_s"_a = 0.5, "start_m"_a = 0.0,
      "Closed-loop velocity run (thesis §2.7, Fig. 2.19), as `microcobot control velocity`: one sample per "
      "sawtooth "
      "period and the metrics.");
  m.def(
      "run_position",
      [](const Plant& p, double target_m, double start_m, double hold_s, double max_time_s) {
        const auto r = nogil([&] {
          return motion::run_position(p.model, p.map, p.params.position, p.params.sensor, start_m, target_m,
                                      hold_s, max_time_s);
        });
        return position_run_dict(r);
      },
      "plant"_a, "target_m"_a, "start_m"_a = 0.0, "hold_s"_a = 0.03, "max_time_s"_a = 0.0,
      "Closed-loop hybrid move from start_m to target_m then hold_s of hold, as `microcobot control "
      "position`.");
  m.def(
      "run_tracking",
      [](const Plant& p, const DoubleArray& setpoints, double setpoint_rate_Hz, const std::string& tracker,
         py::object start, double duration_s) {
        const auto sp = span_of(setpoints, "setpoints_m");
        if (!(setpoint_rate_Hz > 0.0 && setpoint_rate_Hz <= 1e5))
          throw InvalidParams("setpoint_rate_Hz", "in (0, 1e5] Hz", setpoint_rate_Hz);
        const auto kind = studies::parse_tracker_kind(tracker);
        const double half = 0.5 * p.model.params().slider.stroke_m;
        for (std::size_t k = 0; k < sp.size(); ++k)
          if (std::abs(sp[k]) > half)
            throw InvalidParams("setpoints_m[" + std::to_string(k) + "]", "must lie within the stroke",
                                sp[k]);
        const double start_m = start.is_none() ? sp.front() : start.cast<double>();
        if (!std::isfinite(start_m)) throw InvalidParams("start_m", "finite", start_m);
        const double streamed_s = static_cast<double>(sp.size()) / setpoint_rate_Hz;
        if (duration_s <= 0.0) duration_s = streamed_s + 0.05;
        require_budget(duration_s / p.model.dt_s(), kMaxSimulatedSteps, "duration_s",
                       "simulated steps of the tracking run");
        const std::vector<double> values(sp.begin(), sp.end());  // the GIL is released below
        const auto r = nogil([&] {
          // The setpoints are stamped on the sender's clock, k / rate, and read through the
          // stream's bounded look-ahead by the 10 kHz controller: past the
          // last one the stream holds.
          motion::SetpointStream stream(p.params.stream, start_m);
          std::size_t next = 0;
          const auto reference = [&](double t, double dt) {
            for (; next < values.size() && static_cast<double>(next) / setpoint_rate_Hz <= t; ++next)
              stream.push(static_cast<double>(next) / setpoint_rate_Hz, values[next]);
            return stream.sample(t, dt);
          };
          return studies::run_tracker(p.model, p.map, kind, studies::tracker_setup(p.params), start_m,
                                      reference, duration_s);
        });
        const auto& mt = r.metrics;
        return py::dict(
            "t_s"_a = to_array(r.t_s), "ref_m"_a = to_array(r.ref_m), "x_m"_a = to_array(r.x_m),
            "u_V"_a = to_array(r.u_V),
            "metrics"_a = py::dict("rms_error_m"_a = mt.rms_error_m, "max_error_m"_a = mt.max_error_m,
                                   "rms_all_m"_a = mt.rms_all_m, "lag_s"_a = mt.lag_s,
                                   "final_error_m"_a = mt.final_error_m, "edges"_a = mt.edges));
      },
      "plant"_a, "setpoints_m"_a, "setpoint_rate_Hz"_a = 1000.0, "tracker"_a = "tracking",
      "start_m"_a = py::none(), "duration_s"_a = 0.0,
      "Follows position setpoints streamed from Python: setpoints_m [m] at setpoint_rate_Hz "
      "(the console's and the network link's 1 kHz by default) pass through the setpoint stream's "
      "bounded look-ahead (plant params 'stream') into the 10 kHz tracker ('tracking', or the "
      "baselines 'hybrid' and 'thesis-pid'), from start_m (default: the first setpoint) for duration_s "
      "(default: the setpoints' span + 50 ms, holding the last). Returns {'t_s', 'ref_m', 'x_m' (true "
      "position), 'u_V', 'metrics': {'rms_error_m', 'max_error_m' (while the reference moves), "
      "'rms_all_m', 'lag_s', 'final_error_m', 'edges'}}, as `microcobot control trajectory --json`.");
}

void bind_haptics_identification(py::module_& m);

void bind_haptics(py::module_& m) {
  namespace hp = mc::haptics;
  py::class_<hp::RenderPipeline>(
      m, "RenderPipeline",
      "The dual-stage rendering pipeline (thesis §3.3-3.4, eq. 3.7-3.8): LR4 crossover of "
      "the rendered force, the low band to the Pantograph (C_LF), the high band delayed "
      "and compensated (C_HF) to the Haptuator. Per tick or per block.")
      .def(
          py::init([](py::handle p) { return hp::RenderPipeline(params_from<hp::RenderPipelineParams>(p)); }),
          "params"_a = py::none())
      .def_property_readonly("params", [](const hp::RenderPipeline& r) { return params_dict(r.params()); })
      .def(
          "tick",
          [](hp::RenderPipeline& r, double force_N) {
            require(std::isfinite(force_N), "force_N", "must be finite", force_N);
            const auto o = r.tick(force_N);
            return py::make_tuple(o.f_m_N, o.u_V);
          },
          "force_N"_a,
          "One 10 kHz tick: the desired force [N] -> (Pantograph force f_m_N [N], Haptuator u_V [V]).")
      .def(
          "process",
          [](hp::RenderPipeline& r, const DoubleArray& force) {
            const auto f = span_of(force, "force_N");
            py::array_t<double> fm(static_cast<py::ssize_t>(f.size())), u(static_cast<py::ssize_t>(f.size()));
            double* a = fm.mutable_data();
            double* b = u.mutable_data();
            {
              py::gil_scoped_release release;
              for (std::size_t i = 0; i < f.size(); ++i) {
                const auto o = r.tick(f[i]);
                a[i] = o.f_m_N;
                b[i] = o.u_V;
              }
            }
            return py::dict("f_m_N"_a = fm, "u_V"_a = u);
          },
          "force_N"_a, "A block of ticks (the same as tick() on each sample): {'f_m_N', 'u_V'} arrays.")
      .def("reset", &hp::RenderPipeline::reset, "Zeroes the filter and delay-line states.")
      .def("lowpass_response", &hp::RenderPipeline::lowpass_response, "f_Hz"_a,
           "Complex response of the crossover's low band at f_Hz [Hz].")
      .def("highpass_response", &hp::RenderPipeline::highpass_response, "f_Hz"_a,
           "Complex response of the crossover's high band at f_Hz [Hz] (without the alignment delay).");
  bind_haptics_identification(m);
}

namespace {

py::array_t<std::complex<double>> complex_array(const std::vector<std::complex<double>>& v) {
  py::array_t<std::complex<double>> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

py::dict frf_dict(const haptics::ChannelFrf& f) {
  return py::dict("f_Hz"_a = to_array(f.f_Hz), "h"_a = complex_array(f.h),
                  "coherence"_a = to_array(f.coherence));
}

}  // namespace

void bind_haptics_identification(py::module_& m) {
  namespace hp = mc::haptics;
  m.def(
      "identify",
      [](py::handle plant_params, std::uint64_t seed) {
        const hp::DualStagePlant plant(params_from<hp::DualStagePlantParams>(plant_params));
        hp::IdentificationOptions o;
        o.seed = seed;
        const auto id = nogil([&] { return hp::identify(plant, o); });
        const auto& g = id.hf_model;
        return py::dict(
            "lf"_a = frf_dict(id.lf), "hf"_a = frf_dict(id.hf), "lf_gain_m_s2_per_N"_a = id.lf_gain,
            "hf_model"_a = py::dict("b1"_a = g.b1, "b0"_a = g.b0, "a1"_a = g.a1, "a0"_a = g.a0),
            "lf_flat_upper_Hz"_a = id.lf_flat_upper_Hz, "hf_valid_lower_Hz"_a = id.hf_valid_lower_Hz,
            "cutoff_Hz"_a = id.cutoff_Hz, "hf_delay_s"_a = id.hf_delay_s,
            "total_mass_kg"_a = plant.total_mass_kg(), "pipeline"_a = params_dict(hp::pipeline_from(id)));
      },
      "plant"_a = py::none(), "seed"_a = 1,
      "PRBS identification of the dual-stage plant (thesis §3.4, eq. 3.5-3.6), as `microcobot haptics "
      "identify`: "
      "both channels' H1 responses, G_0^LF, the second-order G^HF, the crossover and the high band's "
      "alignment "
      "delay, and the rendering 'pipeline' parameters they give.");
  m.def(
      "evaluate",
      [](py::handle plant_params, py::handle pipeline_params) {
        const hp::DualStagePlant plant(params_from<hp::DualStagePlantParams>(plant_params));
        // As `microcobot haptics evaluate`: the pipeline from the identified plant unless given.
        const bool given = !pipeline_params.is_none();
        hp::RenderPipelineParams rp =
            given ? params_from<hp::RenderPipelineParams>(pipeline_params) : hp::RenderPipelineParams{};
        const auto ev = nogil([&] {
          if (!given) rp = hp::pipeline_from(hp::identify(plant, hp::IdentificationOptions{}));
          return hp::evaluate(plant, rp, hp::EvaluationOptions{});
        });
        return py::dict("fc_Hz"_a = to_array(ev.fc_Hz), "lf_dB"_a = to_array(ev.lf_dB),
                        "hf_dB"_a = to_array(ev.hf_dB), "combined_dB"_a = to_array(ev.combined_dB),
                        "pantograph_dB"_a = to_array(ev.pantograph_dB), "flatness_dB"_a = ev.flatness_dB,
                        "pipeline"_a = params_dict(rp));
      },
      "plant"_a = py::none(), "pipeline"_a = py::none(),
      "Sine-dwell evaluation at the 1/3-octave centres of Table 3.4 (thesis §3.5.1, Fig. 3.13): the gain of "
      "each "
      "channel, of both and of the Pantograph alone [dB]; the pipeline identified from the plant unless "
      "given.");
}

void bind_tweezers(py::module_& m) {
  namespace tw = mc::tweezers;
  m.def("lead_angle", &tw::lead_angle, "diameter_m"_a, "lead_m"_a,
        "Lead angle theta [rad] of a ball screw: tan(theta) = lead / (pi d) (thesis app. B, Fig. B.1).");
  m.def(
      "ball_screw_efficiency",
      [](double d, double lead, double mu) {
        const auto e = tw::ball_screw_efficiency(d, lead, mu);
        return py::dict("lead_angle_rad"_a = e.lead_angle_rad, "forward_efficiency"_a = e.forward_efficiency,
                        "backward_efficiency"_a = e.backward_efficiency);
      },
      "diameter_m"_a, "lead_m"_a, "mu"_a,
      "Forward (eq. B.6) and backward (eq. B.9, sign corrected, erratum 5 in docs/errata.md) efficiencies of "
      "a ball screw.");
  m.def("axial_force", &tw::axial_force, "torque_Nm"_a, "lead_m"_a, "forward_efficiency"_a,
        "Axial force F_a = 2 pi eta_f C / p [N] (eq. 4.4).");
  m.def("finger_force", &tw::finger_force, "axial_force_N"_a, "alpha_rad"_a, "eta_t"_a,
        "Force at each finger F_Y = eta_t (F_a / 2) / tan(alpha) [N] (eq. 4.5).");
  m.def("min_preload", &tw::min_preload, "closing_force_N"_a, "alpha_rad"_a,
        "Magnetic preload keeping the roller on its track [N] (§4.4.2).");
  m.def(
      "identify_bandwidth",
      [](py::handle model, py::handle options) {
        const auto mp = params_from<tw::TeleTweezParams>(model);
        const auto op = params_from<tw::BandwidthIdentParams>(options);
        const auto r = nogil([&] { return tw::identify_bandwidth(mp, op); });
        return py::dict("mode_Hz"_a = r.features.mode_Hz, "antiresonance_Hz"_a = r.features.antiresonance_Hz,
                        "bandwidth_Hz"_a = r.features.bandwidth_Hz, "t_s"_a = to_array(r.t_s),
                        "torque_N_m"_a = to_array(r.torque_N_m), "accel_m_s2"_a = to_array(r.accel_m_s2),
                        "f_Hz"_a = to_array(r.f_Hz), "magnitude"_a = to_array(r.magnitude),
                        "phase_rad"_a = to_array(r.phase_rad), "coherence"_a = to_array(r.coherence),
                        "model_magnitude"_a = to_array(r.model_magnitude));
      },
      "model"_a = py::none(), "options"_a = py::none(),
      "Bandwidth identification of the TéléTweez (thesis §4.5.2, Fig. 4.24-4.25): PRBS torque at 10 kHz, the "
      "H1 "
      "response to the finger acceleration [m/s^2 / (N m)], its mode, antiresonance and flat band [Hz].");
  m.def("stiffness_force", &tw::stiffness_force, "stiffness_N_per_m"_a, "opening_m"_a,
        "Force holding tweezers of clamping stiffness k closed over opening d: F = k d [N] (eq. 4.1).");
}

py::list channels_list(const platform::TelemetrySchema& schema) {
  py::list out;
  for (const auto& ch : schema)
    out.append(py::dict("name"_a = ch.name, "unit"_a = ch.unit, "description"_a = ch.description));
  return out;
}

void bind_platform(py::module_& m) {
  m.def(
      "config", [](py::handle c) { return params_dict(config_from(c)); }, "config"_a = py::none(),
      "The platform configuration (the keys of `microcobot run --print-config`).");
  m.def(
      "run",
      [](const std::string& scenario, double duration_s, py::handle config, py::handle out_dir) {
        const auto c = config_from(config);
        cell::SessionParams sp;
        sp.scenario = scenario;
        sp.max_duration_s = duration_s;
        sp.validate();
        const std::optional<std::string> dir =
            out_dir.is_none() ? std::nullopt : std::optional<std::string>(path_of(out_dir));
        CsvTable table;
        platform::TelemetrySchema channels;
        const auto result = nogil([&] {
          cell::Session session(c, sp);
          auto r = session.run();
          if (dir) session.write(*dir, r);
          table = session.platform().recording().to_table();
          channels = session.platform().telemetry_schema();
          return r;
        });
        return py::dict("result"_a = from_json(result.to_json()), "recording"_a = table_dict(table),
                        "channels"_a = channels_list(channels));
      },
      "scenario"_a = "pick-place", "duration_s"_a = 120.0, "config"_a = py::none(), "out_dir"_a = py::none(),
      "Runs a scenario (pick-place | stale-master) as `microcobot run`: {'result': summary, 'recording': "
      "{column: array}, 'channels': [{'name', 'unit', 'description'}]} (the recording's columns, in order, "
      "e.g. t_s in s); out_dir also writes recording.csv/.mcap and the report.");
  m.def(
      "telemetry_channels",
      [](bool simulation) { return channels_list(platform::builtin_telemetry(simulation)); },
      "simulation"_a = true,
      "The platform's built-in telemetry channels, in a sample's order: [{'name', 'unit', 'description'}] "
      "(the loop's on any devices; with simulation, the simulation's ground truth after them).");
  m.def(
      "read_csv", [](py::handle path) { return table_dict(read_csv(path_of(path))); }, "path"_a,
      "A CSV recording (header row of unit-suffixed names) as {column: array}.");
  m.def(
      "read_mcap", [](py::handle path) { return mcap_dict(read_mcap(path_of(path))); }, "path"_a,
      "An MCAP recording, checked by the strict reader: {topic: {'messages', 'log_time_s', numeric JSON "
      "fields...}}.");
  m.def(
      "read_mat", [](py::handle path) { return read_mat_dict(path_of(path)); }, "path"_a,
      "Every numeric variable of a .mat file as a 2-D float64 array (rows, cols), as scipy.io.loadmat.");
  m.def(
      "write_mat", [](py::handle path, const py::dict& vars) { write_mat_dict(path_of(path), vars); },
      "path"_a, "variables"_a,
      "Writes {name: array} as a MAT 5 file (1-D arrays as N x 1 columns; finite values only; atomic).");
}

}  // namespace mc::py
