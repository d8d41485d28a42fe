// `microcobot stickslip ...`: the stick-slip actuator model of thesis ch. 2 — its parameters, a
// waveform simulator, and the chapter's experiments (Fig. 2.10-2.17) with their figures.

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/core/params.h"
#include "microcobot/stickslip/actuator.h"
#include "microcobot/studies/edge_dip.h"
#include "microcobot/studies/experiment_figures.h"
#include "microcobot/studies/experiments.h"
#include "microcobot/studies/integrator_accuracy.h"

namespace stickslip_commands {
namespace {

namespace ss = mc::stickslip;
using mc::cli::CommonOptions;
using mc::report::Axis;
using mc::report::Figure;
using mc::report::Report;
using mc::report::Series;

ss::StickSlipParams load(const CommonOptions& o) {
  return o.params ? mc::load_params<ss::StickSlipParams>(*o.params) : ss::StickSlipParams{};
}

struct SimulateOptions {
  CommonOptions common;
  std::string wave = "sawtooth";
  double amplitude_V = 40.0;
  double frequency_Hz = 50.0;
  std::string direction = "forward";
  double duration_s = 0.1;
  double dt_s = 0.0;
};

void run_simulate(const SimulateOptions& o) {
  ss::StickSlipParams p = load(o.common);
  if (o.dt_s > 0) p.integrator.dt_s = o.dt_s;
  // Every step is recorded: bound the samples before anything is allocated.
  mc::require_budget(o.duration_s / p.integrator.dt_s, mc::kMaxRecordedSamples, "--duration",
                     "recorded samples (duration / dt)");
  const ss::ActuatorModel m(p);
  const ss::Waveform w = ss::make_waveform(ss::parse_wave_kind(o.wave), o.amplitude_V, o.frequency_Hz,
                                           ss::parse_direction(o.direction), p.drive);
  ss::ActuatorState state = m.initial_state();
  const auto bounds = p.physical_bounds();         // once: it runs the PI over the drive's range
  const std::string where = "stickslip simulate";  // once: a literal would be a string per sample
  // Mean velocity from the same phase to the same phase, over the whole periods after the first
  // (the slider's position within a period swings by up to the PE's stroke): from rest, the first
  // period holds the power-up transient (the hysteresis's initial loading, the contact's first
  // strain: a 20 V drive that never steps slips ~0.26 um there), reported apart as
  // first_period_displacement_m. None for a step. The run's samples are t_k = k dt, k = 0..steps;
  // x(T) and x(t_w) are interpolated between the samples around them.
  const auto steps = static_cast<std::size_t>(std::llround(o.duration_s / m.dt_s()));
  const double planned_s = static_cast<double>(steps) * m.dt_s();
  const double whole_periods =
      w.kind == ss::WaveKind::kStep ? 0.0 : std::floor(planned_s * w.frequency_Hz + 1e-9);
  const double period = w.kind == ss::WaveKind::kStep ? 0.0 : 1.0 / w.frequency_Hz;
  struct Instant {  // x(t) between the samples k and k + 1
    double t = 0.0;
    std::size_t k = 0;
    std::array<double, 2> ts{}, xs{};
    double x() const { return xs[0] + std::clamp((t - ts[0]) / (ts[1] - ts[0]), 0.0, 1.0) * (xs[1] - xs[0]); }
  };
  auto instant = [&](double t) {
    return Instant{t, std::min(steps - 1, static_cast<std::size_t>(t / m.dt_s()))};
  };
  Instant first = instant(period), last = instant(whole_periods * period);
  // Only --out needs the whole trajectory (CSV, .mat, plots): without it the run is streamed and
  // only what the summary needs is kept (so that `simulate --duration 10` runs at >= 40x real time).
  ss::Trajectory tr;
  double x0 = 0.0, xf = 0.0, t0 = 0.0, tf = 0.0;
  std::size_t n = 0;
  if (o.common.out) {
    const std::size_t n_rec = steps + 2;
    tr.t_s.reserve(n_rec);
    tr.u_V.reserve(n_rec);
    tr.x1_m.reserve(n_rec);
    tr.x2_m.reserve(n_rec);
  }
  ss::simulate_each(m, w, o.duration_s, 1, state, [&](const ss::ActuatorState& s) {
    const double x2 = m.slider_position(s), x1 = s.x1_m();
    p.check_physical_bounds(bounds, x1, x2, s.t_s, where);
    if (n == 0) x0 = x2, t0 = s.t_s;
    for (Instant* at : {&first, &last})
      if (n == at->k || n == at->k + 1) at->ts[n - at->k] = s.t_s, at->xs[n - at->k] = x2;
    xf = x2, tf = s.t_s;
    ++n;
    if (o.common.out) {
      tr.t_s.push_back(s.t_s);
      tr.u_V.push_back(s.u_V);
      tr.x1_m.push_back(x1);
      tr.x2_m.push_back(x2);
    }
  });
  const double dur = tf - t0;
  nlohmann::json mean_velocity = nullptr, first_period = nullptr;
  if (whole_periods >= 1.0) first_period = first.x() - x0;
  if (whole_periods >= 2.0) mean_velocity = (last.x() - first.x()) / (last.t - first.t);
  nlohmann::json j{{"wave", o.wave},
                   {"amplitude_V", o.amplitude_V},
                   {"frequency_Hz", o.frequency_Hz},
                   {"direction", o.direction},
                   {"duration_s", dur},
                   {"dt_s", m.dt_s()},
                   {"samples", n},
                   {"final_position_m", xf},
                   {"displacement_m", xf - x0},
                   {"whole_periods", whole_periods},
                   {"steady_periods", std::max(0.0, whole_periods - 1.0)},
                   {"first_period_displacement_m", first_period},
                   {"mean_velocity_m_s", mean_velocity},
                   {"part_separation_m", state.x2_m[0] - state.x2_m[1]}};
  if (o.common.out) {
    mc::ensure_writable_dir(*o.common.out);
    mc::CsvTable t;
    t.add_column("t_s", tr.t_s);
    t.add_column("u_V", tr.u_V);
    t.add_column("x1_m", tr.x1_m);
    t.add_column("x2_m", tr.x2_m);
    // --format mat: results.mat holds the trajectory's columns and the summary's numbers.
    if (!mc::cli::write_results_mat(o.common, j,
                                    {{"t_s", tr.t_s}, {"u_V", tr.u_V}, {"x1_m", tr.x1_m}, {"x2_m", tr.x2_m}}))
      mc::write_csv(
          *o.common.out / "trajectory.csv", t,
          {fmt::format("microcobot stickslip simulate --wave {} --amplitude {} --frequency {} --direction {} "
                       "--duration {}",
                       o.wave, o.amplitude_V, o.frequency_Hz, o.direction, o.duration_s)});
    Report r("stickslip simulate");
    r.section("Simulation", fmt::format("{} {:g} V {:g} Hz {} for {:g} s", o.wave, o.amplitude_V,
                                        o.frequency_Hz, o.direction, dur));
    const std::size_t every = std::max<std::size_t>(1, tr.t_s.size() / 20000);
    Series u{"U", {}, {}, false}, x1{"x1 (PE)", {}, {}, false}, x2{"x2 (slider)", {}, {}, false};
    for (std::size_t i = 0; i < tr.t_s.size(); i += every) {
      u.x.push_back(tr.t_s[i]);
      u.y.push_back(tr.u_V[i]);
      x1.x.push_back(tr.t_s[i]);
      x1.y.push_back(tr.x1_m[i]);
      x2.x.push_back(tr.t_s[i]);
      x2.y.push_back(tr.x2_m[i]);
    }
    r.add_figure(
        {"Positions", "PE and slider displacement.", {"Time", "s"}, {"Displacement", "m"}, {x1, x2}});
    r.add_figure({"Drive", "Drive voltage.", {"Time", "s"}, {"Voltage", "V"}, {u}});
    mc::cli::write_report_if_requested(o.common, r);
  }
  mc::cli::emit(
      o.common, j,
      mean_velocity.is_null()
          ? fmt::format("final position {:.6g} m after {:g} s", xf, dur)
          : fmt::format("final position {:.6g} m after {:g} s; first period {:.6g} m, then mean velocity "
                        "{:.6g} m/s over {:g} whole periods",
                        xf, dur, first_period.get<double>(), mean_velocity.get<double>(),
                        whole_periods - 1.0));
}

struct AccuracyOptions {
  CommonOptions common;
  int drives = 40;
  std::uint64_t seed = 12;
  double rtol = 1e-9;
};

double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(std::lround(q * static_cast<double>(v.size() - 1)))];
}

/// The integrator against the reference solver on drives drawn at random.
void run_accuracy(const AccuracyOptions& o) {
  const ss::ActuatorModel m(load(o.common));
  const auto drives = mc::studies::accuracy_drives(o.drives, o.seed, m.params().drive);
  nlohmann::json cases = nlohmann::json::array();
  std::vector<double> rms, mx, step;
  mc::studies::DriveAccuracy worst;
  std::size_t worst_i = 0;
  for (std::size_t i = 0; i < drives.size(); ++i) {
    const auto& d = drives[i];
    ss::ReferenceOptions ro;
    ro.rel_tol = o.rtol;
    ro.abs_tol_m = o.rtol * 1e-6;
    mc::studies::DriveAccuracy a = mc::studies::check_drive(m, d, ro);
    rms.push_back(a.rms_error);
    mx.push_back(a.max_error);
    step.push_back(a.step_error);
    cases.push_back({{"wave", ss::to_string(d.wave.kind)},
                     {"amplitude_V", d.wave.amplitude_V},
                     {"frequency_Hz", d.wave.kind == ss::WaveKind::kStep ? 0.0 : d.wave.frequency_Hz},
                     {"direction", ss::to_string(d.wave.direction)},
                     {"duration_s", d.duration_s},
                     {"range_m", a.range_m},
                     {"rms_error", a.rms_error},
                     {"max_error", a.max_error},
                     {"step_m", a.step_m},
                     {"step_ref_m", a.step_ref_m},
                     {"step_error", a.step_error},
                     {"steady_periods", a.steady_periods},
                     {"first_period_m", a.first_period_m},
                     {"first_period_ref_m", a.first_period_ref_m}});
    mc::cli::progress("accuracy", i + 1, drives.size());
    if (i == 0 || a.rms_error > worst.rms_error) {
      worst = std::move(a);
      worst_i = i;
    }
  }
  auto stats = [&](const std::vector<double>& v) {
    return nlohmann::json{{"median", quantile(v, 0.5)}, {"max", *std::max_element(v.begin(), v.end())}};
  };
  const nlohmann::json j{{"dt_s", m.dt_s()},        {"drives", o.drives},     {"seed", o.seed},
                         {"rms_error", stats(rms)}, {"max_error", stats(mx)}, {"step_error", stats(step)},
                         {"cases", cases}};
  if (o.common.out) {
    mc::ensure_writable_dir(*o.common.out);
    Report r("stickslip accuracy");
    r.section(
        "Integrator against the reference solver",
        fmt::format("{} drives drawn at random (seed {}), step {:g} s; errors of the slider position as "
                    "fractions of its range, and of the net step per period.",
                    o.drives, o.seed, m.dt_s()));
    Series sr{"RMS error", {}, {}, true}, sm{"max error", {}, {}, true}, ss_{"step error", {}, {}, true};
    for (std::size_t i = 0; i < drives.size(); ++i) {
      const double f = drives[i].wave.kind == ss::WaveKind::kStep ? 1.0 : drives[i].wave.frequency_Hz;
      sr.x.push_back(f);
      sr.y.push_back(rms[i]);
      sm.x.push_back(f);
      sm.y.push_back(mx[i]);
      ss_.x.push_back(f);
      ss_.y.push_back(step[i]);
    }
    r.add_result("RMS error, median", quantile(rms, 0.5), "");
    r.add_result("RMS error, max", *std::max_element(rms.begin(), rms.end()), "");
    r.add_result("step error, max", *std::max_element(step.begin(), step.end()), "");
    r.add_figure({"Errors by drive frequency",
                  "Each drive's errors (steps drawn at 1 Hz).",
                  {"Frequency", "Hz", true},
                  {"Relative error", "", true},
                  {sr, sm, ss_}});
    const auto& w = drives[worst_i].wave;
    r.add_figure(
        {"Largest RMS error: slider position",
         fmt::format("{} {:.1f} V {:.1f} Hz {}: the model at its step and the reference solver.",
                     ss::to_string(w.kind), w.amplitude_V, w.frequency_Hz, ss::to_string(w.direction)),
         {"Time", "s"},
         {"Slider position", "m"},
         {{"model", worst.model.t_s, worst.model.x2_m, false},
          {"reference", worst.reference.t_s, worst.reference.x2_m, false}}});
    mc::cli::write_report_if_requested(o.common, r);
  }
  mc::cli::emit(
      o.common, j,
      fmt::format("{} drives: slider RMS error median {:.3g} %, max {:.3g} % of the range; step per "
                  "period error median {:.3g} %, max {:.3g} %",
                  o.drives, 100 * quantile(rms, 0.5), 100 * *std::max_element(rms.begin(), rms.end()),
                  100 * quantile(step, 0.5), 100 * *std::max_element(step.begin(), step.end())));
}

/// One sweep's rows: the case, what it did.
void add_rows(mc::CsvTable& t, int sweep_id, const std::vector<mc::studies::EdgeDip>& dips) {
  for (const auto& d : dips) {
    const std::array<double, 13> row{static_cast<double>(sweep_id),
                                     d.edge.top_V,
                                     d.edge.drop_V,
                                     d.edge.slew_V_s,
                                     d.edge.ramp_m_s,
                                     d.edge.unload_V,
                                     d.edge.split_delay_s,
                                     d.edge_s,
                                     d.dip_m,
                                     d.dip_at_s,
                                     d.net_m,
                                     d.overshoot_m,
                                     d.z_ba_m};
    t.add_row(row);
  }
}

nlohmann::json fit_json(const mc::studies::PowerFit& f) {
  return {{"exponent", f.exponent}, {"factor", f.factor}, {"points", f.points}};
}

/// The split edges' dip, rest and overshoot against the halves' delay.
std::vector<Series> split_series(const std::vector<mc::studies::EdgeDip>& dips) {
  std::vector<Series> out{
      {"dip", {}, {}, false}, {"rest (behind the start)", {}, {}, false}, {"overshoot", {}, {}, false}};
  for (const auto& d : dips) {
    for (auto& s : out) s.x.push_back(d.edge.split_delay_s);
    out[0].y.push_back(d.dip_m);
    out[1].y.push_back(-d.net_m);
    out[2].y.push_back(d.overshoot_m);
  }
  return out;
}

Series dip_series(const std::string& name, const std::vector<mc::studies::EdgeDip>& dips, bool by_drop) {
  Series s{name, {}, {}, true};
  for (const auto& d : dips) {
    s.x.push_back(by_drop ? d.edge.drop_V : d.edge_s);
    s.y.push_back(d.dip_m);
  }
  return s;
}

/// The edge's dip against its drop, slew and operating point (studies/edge_dip.h).
void run_edge_dip(const CommonOptions& o) {
  const ss::ActuatorModel m(load(o));
  const auto st = mc::studies::run_edge_study(
      m, [](std::size_t done, std::size_t total) { mc::cli::progress("edge-dip", done, total); });
  mc::studies::EdgeCase tracking_edge;  // the tracking controller's: 31.62..100 V, unloaded by 49.16 V
  tracking_edge.unload_V = 49.16;
  const auto tracking = mc::studies::run_edge(m, tracking_edge);
  const nlohmann::json j{{"mechanism", st.mechanism},
                         {"z_ba_m", st.z_ba_m},
                         {"dip_vs_drop", fit_json(st.dip_vs_drop)},
                         {"dip_vs_duration", fit_json(st.dip_vs_duration)},
                         {"dip_vs_drop_unloaded", fit_json(st.dip_vs_drop_unloaded)},
                         {"dip_vs_duration_unloaded", fit_json(st.dip_vs_duration_unloaded)},
                         {"tracking_edge",
                          {{"dip_m", tracking.dip_m},
                           {"dip_at_s", tracking.dip_at_s},
                           {"net_m", tracking.net_m},
                           {"overshoot_m", tracking.overshoot_m},
                           {"edge_s", tracking.edge_s}}},
                         {"least_split_edge",
                          {{"split_delay_s", st.least_split.edge.split_delay_s},
                           {"dip_m", st.least_split.dip_m},
                           {"net_m", st.least_split.net_m},
                           {"overshoot_m", st.least_split.overshoot_m}}}};
  if (o.out) {
    mc::ensure_writable_dir(*o.out);
    mc::CsvTable t({"sweep", "top_V", "drop_V", "slew_V_s", "ramp_m_s", "unload_V", "split_delay_s", "edge_s",
                    "dip_m", "dip_at_s", "net_m", "overshoot_m", "z_ba_m"});
    add_rows(t, 0, st.drop_sweep);
    add_rows(t, 1, st.drop_sweep_unloaded);
    add_rows(t, 2, st.slew_sweep);
    add_rows(t, 3, st.slew_sweep_unloaded);
    add_rows(t, 4, st.speed_sweep);
    add_rows(t, 5, st.top_sweep);
    add_rows(t, 6, st.split_sweep);
    mc::cli::write_result_tables(
        o,
        {{"edges.csv",
          t,
          "edges_",
          {"sweep: 0 drop, 1 drop unloaded, 2 slew, 3 slew unloaded, 4 ramp speed, 5 top voltage, 6 split "
           "edge's delay (unloaded)"}}},
        j);
    Report r("stickslip edge-dip");
    r.section(
        "The dip of one edge",
        fmt::format("A stuck slider ramped at 100 um/s, then one edge: the PE falls by dV at the slew S "
                    "from 100 V (held, or turned back by 72 % of dV: the tracking controller's "
                    "unloading). The dip is the slider's largest excursion behind where it was when the "
                    "edge started. Mechanism from the held edges' fits: {}.",
                    st.mechanism));
    r.add_result("dip ~ dV^p (held, 1 V/us), p", st.dip_vs_drop.exponent, "");
    r.add_result("dip ~ T^p (held, dV 68.38 V), p", st.dip_vs_duration.exponent, "");
    r.add_result("break-away strain z_ba", st.z_ba_m, "m");
    r.add_result("the tracking controller's edge (unloaded): dip", tracking.dip_m, "m");
    r.add_result("the same edge split in two halves: least dip", st.least_split.dip_m, "m");
    r.add_result("... at the halves' delay", st.least_split.edge.split_delay_s, "s");
    r.add_figure(
        {"Dip against the edge's drop",
         "At 1 V/us from 100 V, held and unloaded.",
         {"Drop dV", "V", true},
         {"Dip", "m", true},
         {dip_series("held", st.drop_sweep, true), dip_series("unloaded", st.drop_sweep_unloaded, true)}});
    r.add_figure(
        {"Dip against the edge's duration",
         "dV = 68.38 V at slews from 0.125 to 8 V/us, held and unloaded.",
         {"Edge duration T = dV / S", "s", true},
         {"Dip", "m", true},
         {dip_series("held", st.slew_sweep, false), dip_series("unloaded", st.slew_sweep_unloaded, false)}});
    r.add_figure({"The edge split in two halves",
                  "The tracking controller's edge (68.38 V at 1 V/us, unloaded by 72 %) as two halves, the "
                  "second delayed: the dip, where the slider rests behind the start, and the overshoot "
                  "beyond that rest.",
                  {"Delay between the halves", "s", false},
                  {"Displacement", "m", false},
                  split_series(st.split_sweep)});
    mc::cli::write_report_if_requested(o, r);
  }
  mc::cli::emit(
      o, j,
      fmt::format("mechanism: {}; dip ~ dV^{:.2f} at 1 V/us, ~ T^{:.2f} at 68.38 V (held); unloaded "
                  "dV^{:.2f}, T^{:.2f}; z_ba {:.0f} nm; the tracking controller's edge (unloaded) dips "
                  "{:.0f} nm at {:.0f} us, rests {:+.0f} nm; split in two halves {:.0f} us apart it dips "
                  "{:.0f} nm, rests {:+.0f} nm",
                  st.mechanism, st.dip_vs_drop.exponent, st.dip_vs_duration.exponent,
                  st.dip_vs_drop_unloaded.exponent, st.dip_vs_duration_unloaded.exponent, st.z_ba_m * 1e9,
                  tracking.dip_m * 1e9, tracking.dip_at_s * 1e6, tracking.net_m * 1e9,
                  st.least_split.edge.split_delay_s * 1e6, st.least_split.dip_m * 1e9,
                  st.least_split.net_m * 1e9));
}

void add_stickslip(CLI::App& group) {
  {
    auto o = std::make_shared<CommonOptions>();
    auto* cmd =
        group.add_subcommand("params", "Print every parameter of the actuator model (the --params keys)");
    mc::cli::add_output_options(*cmd, *o);
    mc::cli::add_params_option(*cmd, *o);
    cmd->callback([o] { mc::cli::emit(*o, mc::params_to_json(load(*o)), mc::params_to_yaml(load(*o))); });
  }
  {
    auto o = std::make_shared<SimulateOptions>();
    auto* cmd = group.add_subcommand("simulate", "Run a drive waveform on one axis; CSV t_s,u_V,x1_m,x2_m");
    cmd->add_option("--wave", o->wave, "sawtooth | sine | step")
        ->check(CLI::IsMember({"sawtooth", "sine", "step"}));
    cmd->add_option("--amplitude", o->amplitude_V,
                    "Amplitude [V] (0..100 V, the amplifier's range; the drive starts at 0 V)")
        ->check(mc::cli::NonNegativeNumber);
    cmd->add_option("--frequency", o->frequency_Hz,
                    "Frequency [Hz] (sawtooth: each period starts at 0 V; ignored by a step)")
        ->check(mc::cli::PositiveNumber);
    cmd->add_option("--direction", o->direction, "forward | backward")
        ->check(CLI::IsMember({"forward", "backward"}));
    cmd->add_option("--duration", o->duration_s, "Simulated time [s]")->check(mc::cli::Range(1e-6, 1e4));
    cmd->add_option("--dt", o->dt_s, "Integrator step [s] (default integrator.dt_s)")
        ->check(mc::cli::Range(1e-9, 1e-4));
    mc::cli::add_output_options(*cmd, o->common);
    mc::cli::add_format_option(*cmd, o->common);
    mc::cli::add_params_option(*cmd, o->common);
    cmd->callback([o] { run_simulate(*o); });
  }
  {
    auto o = std::make_shared<AccuracyOptions>();
    auto* cmd = group.add_subcommand(
        "accuracy", "The integrator against the reference solver on drives drawn at random (errors, steps)");
    cmd->add_option("--drives", o->drives, "Number of drives")->check(mc::cli::Range(1, 1000));
    cmd->add_option("--seed", o->seed, "Seed of the drives' generator");
    cmd->add_option("--rtol", o->rtol, "Reference solver's relative tolerance (absolute: rtol x 1 um)")
        ->check(mc::cli::Range(1e-13, 1e-6));
    mc::cli::add_output_options(*cmd, o->common);
    mc::cli::add_params_option(*cmd, o->common);
    cmd->callback([o] { run_accuracy(*o); });
  }
  {
    auto o = std::make_shared<CommonOptions>();
    auto* cmd = group.add_subcommand(
        "edge-dip",
        "One abrupt edge's backward dip against its drop, slew and operating point (the mechanism)");
    mc::cli::add_output_options(*cmd, *o);
    mc::cli::add_format_option(*cmd, *o);
    mc::cli::add_params_option(*cmd, *o);
    cmd->callback([o] { run_edge_dip(*o); });
  }
  {
    auto o = std::make_shared<CommonOptions>();
    auto name = std::make_shared<std::string>();
    auto* cmd = group.add_subcommand("experiment",
                                     "Reproduce a chapter-2 experiment: pe-step, actuator-step, "
                                     "hysteresis, scanning, stepping, threshold, psd");
    cmd->add_option("name", *name, "Experiment name")
        ->required()
        ->check(CLI::IsMember(mc::studies::experiment_names()));
    mc::cli::add_output_options(*cmd, *o);
    mc::cli::add_format_option(*cmd, *o);
    mc::cli::add_params_option(*cmd, *o);
    cmd->callback([o, name] {
      Report r("stickslip experiment " + *name);
      const auto j = mc::studies::experiment_figures(*name, load(*o), r);
      mc::cli::write_results_mat(*o, j);  // --format mat: the summary's numbers and arrays
      mc::cli::write_report_if_requested(*o, r);
      mc::cli::emit(*o, j);
    });
  }
}

const bool kRegistered = mc::cli::register_group(
    {"stickslip", "Piezoelectric stick-slip actuator model (thesis ch. 2): params, simulate, experiment", 30,
     &add_stickslip});

}  // namespace
}  // namespace stickslip_commands
