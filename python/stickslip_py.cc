// microcobot.stickslip and microcobot.identify: the stick-slip axis of thesis ch. 2 (parameters,
// waveform simulation, the chapter's experiments, a batch rollout over threads) and its
// identification (§2.5.2) from numpy arrays or files. Argument conversion only: every number comes
// from the library calls the CLI makes (apps/microcobot/stickslip_commands.cc,
// identify_commands.cc).

#include <algorithm>
#include <atomic>
#include <thread>

#include "common.h"
#include "microcobot/core/csv.h"
#include "microcobot/core/mat_file.h"
#include "microcobot/stickslip/actuator.h"
#include "microcobot/stickslip/ident_all.h"
#include "microcobot/stickslip/ident_breakaway.h"
#include "microcobot/stickslip/ident_friction_modes.h"
#include "microcobot/stickslip/ident_hysteresis.h"
#include "microcobot/stickslip/ident_pe_modes.h"
#include "microcobot/stickslip/ident_record.h"
#include "microcobot/studies/experiments.h"

namespace mc::py {
namespace {

namespace ss = mc::stickslip;
using namespace pybind11::literals;

/// The model from params (dict, file, None) or an Actuator already built.
ss::ActuatorModel model_from(py::handle params, std::optional<double> dt_s) {
  if (py::isinstance<ss::ActuatorModel>(params) && !dt_s) return params.cast<const ss::ActuatorModel&>();
  const auto p = py::isinstance<ss::ActuatorModel>(params) ? params.cast<const ss::ActuatorModel&>().params()
                                                           : params_from<ss::StickSlipParams>(params);
  return dt_s ? ss::ActuatorModel(p, *dt_s) : ss::ActuatorModel(p);
}

py::dict trajectory_dict(const ss::Trajectory& tr) {
  return py::dict("t_s"_a = to_array(tr.t_s), "u_V"_a = to_array(tr.u_V), "x1_m"_a = to_array(tr.x1_m),
                  "x2_m"_a = to_array(tr.x2_m));
}

py::dict spectrum_dict(const dsp::Spectrum& s) {
  return py::dict("f_Hz"_a = to_array(s.f_Hz), "psd"_a = to_array(s.value));
}

py::dict simulate(py::handle params, const std::string& wave, double amplitude_V, double frequency_Hz,
                  const std::string& direction, double duration_s, std::optional<double> dt_s,
                  int record_every) {
  // The calls of `microcobot stickslip simulate` (run_simulate): budget, model, waveform, run,
  // physical bounds.
  const ss::ActuatorModel m = model_from(params, dt_s);
  require(std::isfinite(duration_s) && duration_s > 0.0, "duration_s", "must be > 0", duration_s);
  require_budget(duration_s / m.dt_s() / std::max(record_every, 1), kMaxRecordedSamples, "duration_s",
                 "recorded samples (duration / dt / record_every)");
  const ss::Waveform w = ss::make_waveform(ss::parse_wave_kind(wave), amplitude_V, frequency_Hz,
                                           ss::parse_direction(direction), m.params().drive);
  ss::ActuatorState state = m.initial_state();
  ss::Trajectory tr;
  {
    py::gil_scoped_release release;
    tr = ss::simulate(m, w, duration_s, record_every, &state);
  }
  const auto bounds = m.params().physical_bounds();
  for (std::size_t i = 0; i < tr.t_s.size(); ++i) {
    m.params().check_physical_bounds(bounds, tr.x1_m[i], tr.x2_m[i], tr.t_s[i], "stickslip.simulate");
  }
  return trajectory_dict(tr);
}

py::list cases_list(const std::vector<studies::SawtoothCase>& cases) {
  py::list out;
  for (const auto& c : cases) {
    py::dict d("amplitude_V"_a = c.amplitude_V, "frequency_Hz"_a = c.frequency_Hz,
               "direction"_a = ss::to_string(c.direction), "net_displacement_m"_a = c.net_displacement_m,
               "velocity_m_s"_a = c.velocity_m_s, "stroke_m"_a = c.stroke_m, "stepping"_a = c.stepping);
    d["trajectory"] = trajectory_dict(c.trajectory);
    out.append(d);
  }
  return out;
}

py::dict experiment(const std::string& name, py::handle params) {
  const auto p = params_from<ss::StickSlipParams>(params);
  auto step_result = [](const studies::StepSpectrumResult& r) {
    return py::dict("response"_a = trajectory_dict(r.response), "psd"_a = spectrum_dict(r.psd),
                    "peaks_Hz"_a = to_array(r.peaks_Hz));
  };
  if (name == "pe-step") return step_result(studies::run_pe_step(p));
  if (name == "actuator-step") return step_result(studies::run_actuator_step(p));
  if (name == "hysteresis") {
    py::list loops;
    for (const auto& l : studies::run_hysteresis(p)) {
      loops.append(py::dict("frequency_Hz"_a = l.frequency_Hz, "amplitude_V"_a = l.amplitude_V,
                            "u_V"_a = to_array(l.u_V), "x2_m"_a = to_array(l.x2_m), "area_V_m"_a = l.area_V_m,
                            "range_m"_a = l.range_m));
    }
    return py::dict("loops"_a = loops);
  }
  if (name == "scanning") return py::dict("cases"_a = cases_list(studies::run_scanning(p)));
  if (name == "stepping") return py::dict("cases"_a = cases_list(studies::run_stepping(p)));
  if (name == "threshold") {
    const auto t = studies::run_threshold(p);
    return py::dict("frequency_Hz"_a = t.frequency_Hz, "forward_V"_a = t.forward_V,
                    "backward_V"_a = t.backward_V);
  }
  if (name == "psd") {
    py::list cases;
    for (const auto& c : studies::run_psd(p)) {
      cases.append(py::dict("amplitude_V"_a = c.amplitude_V, "frequency_Hz"_a = c.frequency_Hz,
                            "psd"_a = spectrum_dict(c.psd), "dominant_peak_Hz"_a = c.dominant_peak_Hz));
    }
    return py::dict("cases"_a = cases);
  }
  throw UsageError("unknown experiment '" + name +
                   "' (pe-step, actuator-step, hysteresis, scanning, stepping, threshold, psd)");
}

/// rollout(): N independent axes, each driven by its row of `voltages` (one sample per model step,
/// linear between samples: ActuatorModel::step(state, u)). The axes are spread over `threads`
/// std::threads with the GIL released; outputs are written into arrays allocated before.
py::dict rollout(py::handle params, py::handle initial_states, const DoubleArray& voltages, int threads,
                 py::handle operating_point, py::object out, py::object out_x1) {
  const ss::ActuatorModel m = model_from(params, std::nullopt);
  check_array(voltages, "voltages", 2);
  const auto n = static_cast<std::size_t>(voltages.shape(0));
  const auto steps = static_cast<std::size_t>(voltages.shape(1));
  require(threads >= 0 && threads <= 1024, "threads", "must be in 0..1024 (0: one per core)",
          static_cast<double>(threads));

  std::vector<ss::ActuatorState> states(n, m.initial_state());
  if (!initial_states.is_none()) {
    if (py::isinstance<py::sequence>(initial_states) && py::len(initial_states) > 0 &&
        py::isinstance<ss::ActuatorState>(py::reinterpret_borrow<py::sequence>(initial_states)[0])) {
      const auto seq = py::reinterpret_borrow<py::sequence>(initial_states);
      if (py::len(seq) != n) {
        throw InvalidInput("initial_states: expected " + std::to_string(n) +
                           " states (one per row of voltages), got " + std::to_string(py::len(seq)));
      }
      for (std::size_t i = 0; i < n; ++i) states[i] = seq[i].cast<ss::ActuatorState>();
    } else {
      const auto x0 = initial_states.cast<DoubleArray>();
      check_array(x0, "initial_states", 1);
      if (static_cast<std::size_t>(x0.size()) != n) {
        throw InvalidInput("initial_states: expected " + std::to_string(n) +
                           " slider positions (one per row of voltages), got " + std::to_string(x0.size()));
      }
      const double half = 0.5 * m.params().slider.stroke_m;
      for (std::size_t i = 0; i < n; ++i) {
        if (std::abs(x0.data()[i]) > half) {
          throw InvalidInput("initial_states[" + std::to_string(i) + "]: slider position " +
                             std::to_string(x0.data()[i]) + " m outside the end stops +-" +
                             std::to_string(half) + " m");
        }
        states[i].x2_m = {x0.data()[i], x0.data()[i]};
      }
    }
  }
  if (!operating_point.is_none()) {
    std::tuple<double, double, std::string> op;
    try {
      op = operating_point.cast<std::tuple<double, double, std::string>>();
    } catch (const py::cast_error&) {
      throw InvalidInput("operating_point: expected (amplitude_V, frequency_Hz, 'forward' | 'backward')");
    }
    const auto dir = ss::parse_direction(std::get<2>(op));
    require(std::isfinite(std::get<0>(op)) && std::isfinite(std::get<1>(op)) && std::get<1>(op) > 0,
            "operating_point", "amplitude_V and frequency_Hz must be finite, frequency > 0");
    for (auto& s : states) m.set_operating_point(s, std::get<0>(op), std::get<1>(op), dir);
  }

  // Caller-owned outputs (as MuJoCo's rollout): float64, C-contiguous, shape (N, T), written in
  // place; a caller that reuses them across calls saves the first-touch page faults of fresh ones.
  const auto output = [&](const py::object& given, const char* name) {
    if (given.is_none())
      return py::array_t<double>({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(steps)});
    if (!py::isinstance<py::array_t<double>>(given)) {
      throw InvalidInput(std::string(name) + ": expected a float64 numpy array");
    }
    auto a = given.cast<py::array_t<double>>();
    if (a.ndim() != 2 || static_cast<std::size_t>(a.shape(0)) != n ||
        static_cast<std::size_t>(a.shape(1)) != steps || !(a.flags() & py::array::c_style) ||
        !a.writeable()) {
      throw InvalidInput(std::string(name) + ": expected a writeable C-contiguous float64 array of shape (" +
                         std::to_string(n) + ", " + std::to_string(steps) + ")");
    }
    return a;
  };
  py::array_t<double> x2 = output(out, "out");
  py::array_t<double> x1 = output(out_x1, "out_x1");
  const double* const x2_begin = x2.data();
  const double* const x1_begin = x1.data();
  if (n * steps > 0 && x1_begin < x2_begin + n * steps && x2_begin < x1_begin + n * steps) {
    throw InvalidInput("out_x1: must not share memory with out");
  }
  const double* u = voltages.data();
  double* x2_out = x2.mutable_data();
  double* x1_out = x1.mutable_data();
  {
    py::gil_scoped_release release;
    const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
    const std::size_t workers =
        std::min<std::size_t>(n, threads == 0 ? hw : static_cast<std::size_t>(threads));
    // Axes are handed out one at a time (their costs differ with the sub-stepping).
    std::atomic<std::size_t> next{0};
    auto work = [&] {
      // The model is copied too: the caller's lies on the calling thread's stack, near what that
      // thread writes every step (docs/benchmarks.md, Python rollout).
      const ss::ActuatorModel model = m;
      for (std::size_t i = next.fetch_add(1); i < n; i = next.fetch_add(1)) {
        // Stepped in a copy owned by this thread: neighbouring axes' states (and their PI
        // operators) share cache lines, which two threads writing every sub-step would ping-pong.
        ss::ActuatorState s = states[i];
        const double* ui = u + i * steps;
        double* xo = x2_out + i * steps;
        double* x1o = x1_out + i * steps;
        for (std::size_t k = 0; k < steps && !s.diverged; ++k) {
          model.step(s, ui[k]);
          xo[k] = model.slider_position(s);
          x1o[k] = s.x1_m();
        }
        states[i] = std::move(s);
      }
    };
    std::vector<std::thread> pool;
    for (std::size_t w = 1; w < workers; ++w) pool.emplace_back(work);
    work();
    for (auto& t : pool) t.join();
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (states[i].diverged) {
      throw ComputationFailed("rollout: axis " + std::to_string(i) +
                              " diverged (NaN/Inf) at t = " + std::to_string(states[i].t_s) +
                              " s; reduce integrator.dt_s or check the parameters");
    }
  }
  py::array_t<double> t(static_cast<py::ssize_t>(steps));
  for (std::size_t k = 0; k < steps; ++k) t.mutable_data()[k] = static_cast<double>(k + 1) * m.dt_s();
  py::list final_states;
  for (const auto& s : states) final_states.append(py::cast(s));
  return py::dict("t_s"_a = t, "x1_m"_a = x1, "x2_m"_a = x2, "states"_a = final_states);
}

// ---- identification -------------------------------------------------------------------------

/// A measured record from arrays t, u, x (SI), or from a file (CSV t_s,u_V,x_m, or .mat t,u,x).
ss::MeasuredRecord record_from(py::handle t_or_file, py::handle u, py::handle x, const std::string& name) {
  if (u.is_none() && x.is_none()) {
    const auto path = py::str(py::module_::import("os").attr("fspath")(t_or_file)).cast<std::string>();
    return ss::read_record(path);
  }
  if (u.is_none() || x.is_none()) throw InvalidInput(name + ": give t, u and x (arrays), or one file name");
  const auto ta = t_or_file.cast<DoubleArray>(), ua = u.cast<DoubleArray>(), xa = x.cast<DoubleArray>();
  const auto ts = span_of(ta, name + ".t"), us = span_of(ua, name + ".u"), xs = span_of(xa, name + ".x");
  if (us.size() != ts.size() || xs.size() != ts.size()) {
    throw InvalidInput(name + ": t, u and x must have the same length (got " + std::to_string(ts.size()) +
                       ", " + std::to_string(us.size()) + ", " + std::to_string(xs.size()) + ")");
  }
  CsvTable table;
  table.add_column("t_s", std::vector<double>(ts.begin(), ts.end()));
  table.add_column("u_V", std::vector<double>(us.begin(), us.end()));
  table.add_column("x_m", std::vector<double>(xs.begin(), xs.end()));
  return ss::record_from_table(table, name);
}

bool is_path(py::handle h) { return py::isinstance<py::str>(h) || py::hasattr(h, "__fspath__"); }

std::string path_of(py::handle h) {
  return py::str(py::module_::import("os").attr("fspath")(h)).cast<std::string>();
}

/// A record given as a file name or as a dict {'t', 'u', 'x'} of arrays (SI units).
ss::MeasuredRecord record_entry(py::handle v, const std::string& name) {
  if (is_path(v)) return ss::read_record(path_of(v));
  if (!py::isinstance<py::dict>(v)) {
    throw InvalidInput(name + ": expected a file name or a dict {'t', 'u', 'x'} of arrays");
  }
  const auto d = py::reinterpret_borrow<py::dict>(v);
  for (const char* k : {"t", "u", "x"}) {
    if (!d.contains(k)) throw InvalidInput(name + ": missing '" + k + "' (a dict {'t', 'u', 'x'} of arrays)");
  }
  return record_from(d["t"], d["u"], d["x"], name);
}

/// Sawtooth runs: a directory of sawtooth_*.csv, or a sequence of dicts {'t', 'u', 'x',
/// 'amplitude_V', 'frequency_Hz', 'direction'}.
std::vector<ss::SawtoothRun> sawtooth_runs_from(py::handle v, const std::string& name) {
  if (is_path(v)) return ss::read_sawtooth_runs(path_of(v));
  if (!py::isinstance<py::sequence>(v)) {
    throw InvalidInput(name +
                       ": expected a directory or a list of dicts {'t', 'u', 'x', 'amplitude_V', "
                       "'frequency_Hz', 'direction'}");
  }
  const auto seq = py::reinterpret_borrow<py::sequence>(v);
  if (py::len(seq) == 0) throw InvalidInput(name + ": no run (step 3 needs at least one)");
  std::vector<ss::SawtoothRun> runs;
  for (std::size_t i = 0; i < py::len(seq); ++i) {
    const std::string where = name + "[" + std::to_string(i) + "]";
    ss::SawtoothRun r;
    r.name = where;
    r.rec = record_entry(seq[i], where);
    const auto d = py::reinterpret_borrow<py::dict>(seq[i]);
    for (const char* k : {"amplitude_V", "frequency_Hz", "direction"}) {
      if (!d.contains(k)) throw InvalidInput(where + ": missing '" + k + "'");
    }
    r.amplitude_V = d["amplitude_V"].cast<double>();
    r.frequency_Hz = d["frequency_Hz"].cast<double>();
    require(std::isfinite(r.amplitude_V) && r.amplitude_V > 0.0, where + ".amplitude_V", "must be > 0 V",
            r.amplitude_V);
    require(std::isfinite(r.frequency_Hz) && r.frequency_Hz > 0.0, where + ".frequency_Hz", "must be > 0 Hz",
            r.frequency_Hz);
    r.direction = ss::parse_direction(d["direction"].cast<std::string>());
    runs.push_back(std::move(r));
  }
  return runs;
}

/// The records of the whole identification: a directory, or a dict {'pe_step' (optional), 'step',
/// 'sine', 'sawtooth'} of records (record_entry) and runs (sawtooth_runs_from).
ss::IdentificationRecords records_from(py::handle v) {
  if (is_path(v)) return ss::read_identification_records(path_of(v));
  if (!py::isinstance<py::dict>(v)) {
    throw InvalidInput("records: expected a directory or a dict {'pe_step', 'step', 'sine', 'sawtooth'}");
  }
  const auto d = py::reinterpret_borrow<py::dict>(v);
  for (const auto& [k, _] : d) {
    const auto key = py::str(k).cast<std::string>();
    if (key != "pe_step" && key != "step" && key != "sine" && key != "sawtooth") {
      throw InvalidInput("records: unknown key '" + key + "' (pe_step, step, sine, sawtooth)");
    }
  }
  for (const char* k : {"step", "sine", "sawtooth"}) {
    if (!d.contains(k)) throw InvalidInput(std::string("records: missing '") + k + "'");
  }
  ss::IdentificationRecords r;
  if (d.contains("pe_step") && !d["pe_step"].is_none())
    r.pe_step = record_entry(d["pe_step"], "records.pe_step");
  r.step = record_entry(d["step"], "records.step");
  r.sine = record_entry(d["sine"], "records.sine");
  r.sawtooth = sawtooth_runs_from(d["sawtooth"], "records.sawtooth");
  return r;
}

py::dict mode_dict(const ss::ModeEstimate& m) {
  return py::dict("frequency_Hz"_a = m.frequency_Hz, "damping_ratio"_a = m.damping_ratio);
}

py::dict pe_dict(const ss::PeModesResult& r) {
  return py::dict("mode_a"_a = mode_dict(r.a), "mode_b"_a = mode_dict(r.b),
                  "gain_fraction_a"_a = r.gain_fraction_a, "static_gain_m_V"_a = r.static_gain_m_V,
                  "step_V"_a = r.step_V, "rms_m"_a = r.rms_m, "psd_peaks_Hz"_a = to_array(r.psd_peaks_Hz),
                  "psd"_a = spectrum_dict(r.psd), "fitted_m"_a = to_array(r.fitted_m),
                  "params"_a = params_dict(r.params));
}

py::dict friction_dict(const ss::FrictionModesResult& r) {
  return py::dict("mode_a"_a = mode_dict(r.a), "mode_b"_a = mode_dict(r.b),
                  "mass_fraction_a"_a = r.mass_fraction_a, "static_gain_m_V"_a = r.static_gain_m_V,
                  "step_V"_a = r.step_V, "rms_m"_a = r.rms_m, "psd_peaks_Hz"_a = to_array(r.psd_peaks_Hz),
                  "psd"_a = spectrum_dict(r.psd), "fitted_m"_a = to_array(r.fitted_m),
                  "params"_a = params_dict(r.params));
}

py::dict hysteresis_dict(const ss::HysteresisResult& r) {
  return py::dict(
      "pi"_a = params_dict(r.pi), "inverse"_a = params_dict(r.inverse),
      "static_gain_m_V"_a = r.static_gain_m_V, "offset_m"_a = r.offset_m, "rms_m"_a = r.rms_m,
      "stroke_m"_a = r.stroke_m, "rms_fraction"_a = r.rms_fraction,
      "inverse_max_error_V"_a = r.inverse_max_error_V, "first_fitted"_a = r.first_fitted,
      "from_rest"_a = r.from_rest,
      "rms_from_rest_m"_a = std::isfinite(r.rms_from_rest_m) ? py::object(py::float_(r.rms_from_rest_m))
                                                             : py::object(py::none()),
      "rms_steady_loop_m"_a = std::isfinite(r.rms_steady_loop_m) ? py::object(py::float_(r.rms_steady_loop_m))
                                                                 : py::object(py::none()),
      "voltage_noise_V"_a = r.voltage_noise_V, "fitted_m"_a = to_array(r.fitted_m));
}

py::dict breakaway_dict(const ss::BreakawayResult& r) {
  py::list runs;
  for (const auto& x : r.runs) {
    runs.append(py::dict("name"_a = x.name, "amplitude_V"_a = x.amplitude_V,
                         "frequency_Hz"_a = x.frequency_Hz, "direction"_a = ss::to_string(x.direction),
                         "v_measured_m_s"_a = x.v_measured_m_s, "v_simulated_m_s"_a = x.v_simulated_m_s,
                         "z_ba_m"_a = x.z_ba_m, "simulations"_a = x.simulations, "ok"_a = x.ok,
                         "skipped"_a = x.skipped));
  }
  return py::dict("runs"_a = runs, "table"_a = params_dict(r.table), "filled"_a = r.filled,
                  "extrapolated"_a = r.extrapolated, "skipped"_a = r.skipped);
}

}  // namespace

void bind_stickslip(py::module_& m) {
  py::class_<ss::ActuatorState>(m, "ActuatorState",
                                "The state of one axis (plain data; copy with copy.copy or .copy()).")
      .def(py::init<>())
      .def(
          "copy", [](const ss::ActuatorState& s) { return s; }, "An independent copy of the state.")
      .def("__copy__", [](const ss::ActuatorState& s) { return s; })
      .def("__deepcopy__", [](const ss::ActuatorState& s, py::dict) { return s; })
      .def_readonly("t_s", &ss::ActuatorState::t_s, "Time [s]")
      .def_readonly("u_V", &ss::ActuatorState::u_V, "Last drive voltage [V]")
      .def_property_readonly("x1_m", &ss::ActuatorState::x1_m, "PE displacement x1 [m] (eq. 2.3)")
      .def_readonly("x2_parts_m", &ss::ActuatorState::x2_m, "Positions of the slider's two parts [m]")
      .def_readonly("v2_parts_m_s", &ss::ActuatorState::v2_m_s, "Velocities of the slider's two parts [m/s]")
      .def_readonly("z_m", &ss::ActuatorState::z_m, "Elastic strain of asperities a, b [m] (eq. 2.9)")
      .def_readonly("friction_N", &ss::ActuatorState::friction_N, "Friction force on the slider [N]")
      .def_readonly("z_ba_m", &ss::ActuatorState::z_ba_m, "Break-away strain in use [m]")
      .def_readonly("diverged", &ss::ActuatorState::diverged, "True once a state became NaN/Inf");

  py::class_<ss::DriveSegment>(
      m, "DriveSegment",
      "The drive over one model step: corners (fractions of the step, voltages [V]) and "
      "the end voltage [V]; what the controllers' next_drive() returns.")
      .def(py::init([](double end_V) { return ss::DriveSegment::to(end_V); }), "end_V"_a)
      .def_readonly("end_V", &ss::DriveSegment::end_V)
      .def_property_readonly("corners", [](const ss::DriveSegment& d) {
        py::list l;
        for (int i = 0; i < d.corners; ++i) {
          l.append(py::make_tuple(d.at[static_cast<std::size_t>(i)], d.u_V[static_cast<std::size_t>(i)]));
        }
        return l;
      });

  py::class_<ss::ActuatorModel>(m, "Actuator",
                                "One stick-slip axis (thesis ch. 2: eq. 2.1-2.21): immutable parameters and "
                                "integrator; drives any number of ActuatorState.")
      .def(py::init([](py::handle params, std::optional<double> dt_s) { return model_from(params, dt_s); }),
           "params"_a = py::none(), "dt_s"_a = py::none(),
           "params: dict, YAML file or None (defaults); dt_s: integrator step [s] (default integrator.dt_s).")
      .def_property_readonly("dt_s", &ss::ActuatorModel::dt_s, "Integrator step [s]")
      .def_property_readonly(
          "params", [](const ss::ActuatorModel& a) { return params_dict(a.params()); },
          "Every parameter as a dict")
      .def(
          "initial_state",
          [](const ss::ActuatorModel& a, std::optional<double> x2) {
            auto s = a.initial_state();
            if (x2) {
              require_in_range(*x2, -0.5 * a.params().slider.stroke_m, 0.5 * a.params().slider.stroke_m,
                               "slider_position_m");
              s.x2_m = {*x2, *x2};
            }
            return s;
          },
          "slider_position_m"_a = py::none(),
          "A state at rest at U = 0 V (slider at slider.initial_position_m or "
          "slider_position_m [m]).")
      .def(
          "set_operating_point",
          [](const ss::ActuatorModel& a, ss::ActuatorState& s, double amplitude_V, double frequency_Hz,
             const std::string& direction) {
            a.set_operating_point(s, amplitude_V, frequency_Hz, ss::parse_direction(direction));
          },
          "state"_a, "amplitude_V"_a, "frequency_Hz"_a, "direction"_a = "forward",
          "Sets the break-away strain z_ba from the table at the sawtooth's operating point (thesis §2.7).")
      .def(
          "step",
          [](const ss::ActuatorModel& a, ss::ActuatorState& s, double u_V) {
            require(std::isfinite(u_V), "u_V", "must be finite", u_V);
            a.step(s, u_V);
            if (s.diverged) {
              throw ComputationFailed("stick-slip step diverged (NaN/Inf) at t = " + std::to_string(s.t_s) +
                                      " s");
            }
          },
          "state"_a, "u_V"_a,
          "Advances `state` by dt_s with the drive linear from state.u_V to u_V [V] (clamped to the "
          "amplifier).")
      .def(
          "step",
          [](const ss::ActuatorModel& a, ss::ActuatorState& s, const ss::DriveSegment& d) {
            a.step(s, d);
            if (s.diverged) {
              throw ComputationFailed("stick-slip step diverged (NaN/Inf) at t = " + std::to_string(s.t_s) +
                                      " s");
            }
          },
          "state"_a, "drive"_a,
          "Advances `state` by dt_s along a DriveSegment (a controller's next_drive()).")
      .def("slider_position", &ss::ActuatorModel::slider_position, "state"_a, "Slider position x2 [m]")
      .def("slider_velocity", &ss::ActuatorModel::slider_velocity, "state"_a, "Slider velocity [m/s]");

  m.def(
      "params", [](py::handle params) { return params_dict(params_from<ss::StickSlipParams>(params)); },
      "params"_a = py::none(),
      "Every parameter of the axis (defaults overridden by a dict or a YAML file), validated. The keys of "
      "`microcobot stickslip params --json`.");
  m.def(
      "save_params",
      [](py::handle params, py::handle path) {
        const auto file = py::str(py::module_::import("os").attr("fspath")(path)).cast<std::string>();
        write_file_atomic(file, params_to_yaml(params_from<ss::StickSlipParams>(params)));
      },
      "params"_a, "path"_a, "Writes validated parameters as a YAML file that --params and params() read.");
  m.def(
      "simulate", &simulate, "params"_a = py::none(), "wave"_a = "sawtooth", "amplitude_V"_a = 40.0,
      "frequency_Hz"_a = 50.0, "direction"_a = "forward", "duration_s"_a = 0.1, "dt_s"_a = py::none(),
      "record_every"_a = 1,
      "Runs a drive waveform (sawtooth | sine | step, thesis Fig. 2.3) on one axis, as `microcobot stickslip "
      "simulate`. Returns {'t_s', 'u_V', 'x1_m', 'x2_m'} (numpy arrays; pandas.DataFrame takes it as is).");
  m.def(
      "experiment", &experiment, "name"_a, "params"_a = py::none(),
      "One chapter-2 experiment (thesis §2.5, Fig. 2.10-2.17): pe-step, actuator-step, hysteresis, scanning, "
      "stepping, threshold, psd. Returns its results as a dict.");
  m.def("experiment_names", &studies::experiment_names, "Names experiment() accepts.");
  m.def(
      "rollout", &rollout, "params"_a, "initial_states"_a, "voltages"_a, "threads"_a = 1,
      "operating_point"_a = py::none(), "out"_a = py::none(), "out_x1"_a = py::none(),
      "N independent axes driven by voltages[N, T] [V] (one sample per model step, linear between samples). "
      "initial_states: None, slider positions [m] of shape (N,), or N ActuatorState. operating_point: "
      "(amplitude_V, frequency_Hz, direction) for z_ba. The GIL is released and the axes spread over "
      "`threads` "
      "threads (0: one per core). Returns {'t_s' (T,), 'x1_m' (N, T), 'x2_m' (N, T), 'states' (final)}; "
      "x2_m is `out` and x1_m is `out_x1` when given (float64, C-contiguous, (N, T), written in place).");
}

void bind_identify(py::module_& m) {
  m.def(
      "record",
      [](py::handle t, py::handle u, py::handle x) {
        const auto r = record_from(t, u, x, "record");
        return py::dict("t_s"_a = to_array(r.t_s), "u_V"_a = to_array(r.u_V), "x_m"_a = to_array(r.x_m));
      },
      "t"_a, "u"_a = py::none(), "x"_a = py::none(),
      "A measured record checked as identification takes it (uniform sampling, >= 16 samples): from arrays t "
      "[s], "
      "u [V], x [m], or from one file (CSV t_s,u_V,x_m or .mat with variables t, u, x).");
  m.def(
      "pe_modes",
      [](py::handle t, py::handle u, py::handle x, py::handle params) {
        const auto base = params_from<ss::StickSlipParams>(params);
        const auto rec = record_from(t, u, x, "pe_modes");
        const auto r = nogil([&] { return ss::identify_pe_modes(rec, base.pe); });
        return pe_dict(r);
      },
      "t"_a, "u"_a = py::none(), "x"_a = py::none(), "params"_a = py::none(),
      "Step 1a (thesis §2.5.2.1, Fig. 2.10): the PE's two modes from its step response without slider "
      "(x = x1 [m]). Returns the modes, gain split, diagnostics and the identified 'params' (pe).");
  m.def(
      "friction_modes",
      [](py::handle t, py::handle u, py::handle x, py::handle params) {
        const auto base = params_from<ss::StickSlipParams>(params);
        const auto rec = record_from(t, u, x, "friction_modes");
        const auto r = nogil([&] { return ss::identify_friction_modes(rec, base); });
        return friction_dict(r);
      },
      "t"_a, "u"_a = py::none(), "x"_a = py::none(), "params"_a = py::none(),
      "Step 1b (thesis §2.5.2.1, Fig. 2.11): the two asperities (rho0, rho1; eq. 2.20-2.21) from the "
      "actuator's step response (x = slider position x2 [m]).");
  m.def(
      "hysteresis",
      [](py::handle t, py::handle u, py::handle x, int operators, py::handle params) {
        std::optional<ss::StickSlipParams> base;
        if (!params.is_none()) base = params_from<ss::StickSlipParams>(params);
        const auto rec = record_from(t, u, x, "hysteresis");
        const auto r =
            nogil([&] { return ss::identify_hysteresis(rec, operators, base ? &*base : nullptr); });
        return hysteresis_dict(r);
      },
      "t"_a, "u"_a = py::none(), "x"_a = py::none(), "operators"_a = 35, "params"_a = py::none(),
      "Step 2 (thesis §2.5.2.2, eq. 2.5, Fig. 2.12): the Prandtl-Ishlinskii thresholds and weights (NNLS) "
      "from a "
      "sine response in scanning mode.");
  m.def(
      "breakaway",
      [](py::handle runs_in, py::handle params, unsigned threads) {
        const auto base = params_from<ss::StickSlipParams>(params);
        ss::BreakawayOptions bo;
        bo.threads = threads;
        const auto runs = sawtooth_runs_from(runs_in, "runs");
        const auto r = nogil([&] {
          const ss::ActuatorModel model(base);
          return ss::identify_breakaway(runs, model, bo);
        });
        return breakaway_dict(r);
      },
      "runs"_a, "params"_a = py::none(), "threads"_a = 0,
      "Step 3 (thesis §2.5.2.3, Fig. 2.13): z_ba of every sawtooth run and the table z_ba(amplitude, "
      "frequency, direction). runs: a directory of sawtooth_<A>V_<f>Hz_<direction>.csv, or a list of dicts "
      "{'t' [s], 'u' [V], 'x' [m] (arrays), 'amplitude_V', 'frequency_Hz', 'direction'}.");
  m.def(
      "all",
      [](py::handle records_in, py::handle params, int operators) {
        const auto base = params_from<ss::StickSlipParams>(params);
        ss::IdentifyAllOptions io;
        io.operators = operators;
        const auto records = records_from(records_in);
        const auto r = nogil([&] { return ss::identify_all(records, base, io); });
        py::dict d("friction"_a = friction_dict(r.friction), "hysteresis"_a = hysteresis_dict(r.hysteresis),
                   "breakaway"_a = breakaway_dict(r.breakaway), "params"_a = params_dict(r.params),
                   "notes"_a = r.notes);
        d["pe"] = r.pe ? py::object(pe_dict(*r.pe)) : py::none();
        return d;
      },
      "records"_a, "params"_a = py::none(), "operators"_a = 35,
      "The whole identification (thesis §2.5.2 steps 1-3): each step's diagnostics and the identified "
      "'params'. records: a directory (pe_step.csv optional, step.csv, sine.csv, sawtooth_*.csv), or a dict "
      "{'pe_step' (optional), 'step', 'sine': a file name or {'t', 'u', 'x'} of arrays; 'sawtooth': as "
      "breakaway()'s runs}.");
}

}  // namespace mc::py
