// `microcobot haptics ...`: the dual-stage haptic interface of thesis ch. 3 (identify, evaluate,
// optical-tweezers replay) and its part of the full report.

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/core/params.h"
#include "microcobot/haptics/evaluation.h"
#include "microcobot/haptics/identification.h"
#include "microcobot/microworld/tweezers_scenario.h"
#include "microcobot/report/report.h"
#include "microcobot/studies/haptics_figures.h"

namespace haptics_commands {
namespace {

namespace hp = mc::haptics;
namespace mw = mc::microworld;
using mc::report::Figure;
using mc::report::Report;
using mc::report::Series;

/// The defaults, or --params FILE over them. A value out of range is reported with the file.
mc::studies::HapticsParams load(const mc::cli::CommonOptions& o) {
  if (!o.params) return mc::studies::HapticsParams{};
  try {
    return mc::load_params<mc::studies::HapticsParams>(*o.params);
  } catch (const mc::InvalidParams& e) {
    throw mc::InvalidInput(o.params->string(), 0, e.what());
  }
}

double db(std::complex<double> z) { return 20.0 * std::log10(std::max(std::abs(z), 1e-300)); }

// ---- identify ---------------------------------------------------------------------------

nlohmann::json identify_json(const hp::IdentificationResult& id) {
  return {{"cutoff_Hz", id.cutoff_Hz},
          {"lf_gain", id.lf_gain},
          {"hf_num", {id.hf_model.b1, id.hf_model.b0}},
          {"hf_den", {1.0, id.hf_model.a1, id.hf_model.a0}},
          {"lf_flat_upper_Hz", id.lf_flat_upper_Hz},
          {"hf_valid_lower_Hz", id.hf_valid_lower_Hz},
          {"hf_delay_s", id.hf_delay_s}};
}

mc::CsvTable frf_table(const hp::ChannelFrf& f) {
  mc::CsvTable t;
  std::vector<double> mag, ph;
  for (const auto& h : f.h) {
    mag.push_back(db(h));
    ph.push_back(std::arg(h) * 180.0 / std::numbers::pi);
  }
  t.add_column("f_Hz", f.f_Hz);
  t.add_column("mag_dB", mag);
  t.add_column("phase_deg", ph);
  t.add_column("coherence", f.coherence);
  return t;
}

void run_identify(const mc::cli::CommonOptions& o) {
  const mc::studies::HapticsParams p = load(o);
  const hp::DualStagePlant plant(p.plant);
  const auto id = hp::identify(plant, hp::IdentificationOptions{});
  if (o.out) {
    const mc::CsvTable lf = frf_table(id.lf), hf = frf_table(id.hf);
    mc::cli::write_result_tables(o, {{"frf_lf.csv", lf, "lf_", {}}, {"frf_hf.csv", hf, "hf_", {}}},
                                 identify_json(id));
    Report r("haptics identify");
    mc::studies::identify_report(r, id);
    mc::cli::write_report_if_requested(o, r);
  }
  mc::cli::emit(o, identify_json(id));
}

// ---- evaluate ---------------------------------------------------------------------------

void run_evaluate(const mc::cli::CommonOptions& o) {
  const mc::studies::HapticsParams p = load(o);
  const hp::DualStagePlant plant(p.plant);
  const auto id = hp::identify(plant, hp::IdentificationOptions{});
  const auto rp = hp::pipeline_from(id, p.pipeline);
  const auto ev = hp::evaluate(plant, rp, hp::EvaluationOptions{});
  // The same columns go to evaluation.csv and to the json summary.
  const std::pair<const char*, const std::vector<double>*> columns[] = {{"fc_Hz", &ev.fc_Hz},
                                                                        {"lf_dB", &ev.lf_dB},
                                                                        {"hf_dB", &ev.hf_dB},
                                                                        {"combined_dB", &ev.combined_dB},
                                                                        {"pantograph_dB", &ev.pantograph_dB}};
  nlohmann::json j{{"flatness_dB", ev.flatness_dB},
                   {"cutoff_Hz", rp.cutoff_Hz},
                   {"f_max_Hz", rp.f_max_Hz},
                   {"hf_delay_s", rp.hf_delay_s}};
  mc::CsvTable t;
  for (const auto& [name, values] : columns) {
    t.add_column(name, *values);
    j[name] = *values;
  }
  if (o.out) {
    mc::cli::write_result_tables(o, {{"evaluation.csv", t, "", {"microcobot haptics evaluate"}}}, j);
    Report r("haptics evaluate");
    mc::studies::evaluate_report(r, ev, rp);
    mc::cli::write_report_if_requested(o, r);
  }
  mc::cli::emit(o, j);
}

// ---- tweezers ---------------------------------------------------------------------------

struct TweezersCmd {
  mc::cli::CommonOptions common;
  std::string scenario = "brownian";
  double duration_s = 2.0;
};

void run_tweezers(const TweezersCmd& c) {
  const auto sc = mw::parse_scenario(c.scenario);
  const mc::studies::HapticsParams p = load(c.common);
  const mc::studies::TweezersOut t = mc::studies::run_tweezers_core(p, sc, c.duration_s);
  const bool contact = sc == mw::TweezersScenario::kContact;
  nlohmann::json j{{"r2", t.stats.r2},
                   {"kurtosis", t.stats.kurtosis},
                   {"corner_Hz", t.corner_Hz},
                   {"expected_corner_Hz", t.expected_corner_Hz},
                   {"scenario", c.scenario}};
  if (contact) {
    j["contact_time_s"] = t.rec.contact_time_s;
    j["force_peak_time_s"] = t.peak_time_s;
  }
  if (c.common.out) {
    mc::CsvTable tab;
    tab.add_column("t_s", t.rec.t_s);
    tab.add_column("bead_y_m", t.rec.bead_y_m);
    tab.add_column("trap_y_m", t.rec.trap_y_m);
    tab.add_column("force_y_N", t.rec.force_y_N);
    tab.add_column("hand_force_N", t.rec.hand_force_N);
    tab.add_column("accel_m_s2", t.accel);
    mc::cli::write_result_tables(
        c.common, {{"tweezers.csv", tab, "", {"microcobot haptics tweezers --scenario " + c.scenario}}}, j);
    Report r("haptics tweezers");
    mc::studies::tweezers_report(r, t, contact);
    mc::cli::write_report_if_requested(c.common, r);
  }
  mc::cli::emit(c.common, j);
}

// ---- registration -----------------------------------------------------------------------

/// A verb with the common options (--json, --out, --params) bound to `o`.
CLI::App* add_verb(CLI::App& group, const std::string& name, const std::string& help,
                   mc::cli::CommonOptions& o) {
  auto* cmd = group.add_subcommand(name, help);
  mc::cli::add_output_options(*cmd, o);
  mc::cli::add_params_option(*cmd, o);
  return cmd;
}

void add_haptics(CLI::App& group) {
  auto params = std::make_shared<mc::cli::CommonOptions>();
  add_verb(group, "params", "Print the default parameters (plant, pipeline, trap)", *params)
      ->callback([params] { mc::cli::emit(*params, mc::params_to_json(load(*params))); });
  auto identify = std::make_shared<mc::cli::CommonOptions>();
  auto* id_cmd =
      add_verb(group, "identify", "PRBS identification of both channels and the cut-off (§3.4.2)", *identify);
  mc::cli::add_format_option(*id_cmd, *identify);
  id_cmd->callback([identify] { run_identify(*identify); });
  auto evaluate = std::make_shared<mc::cli::CommonOptions>();
  auto* ev_cmd =
      add_verb(group, "evaluate", "1/3-octave sine-dwell evaluation of the pipeline (Fig. 3.13)", *evaluate);
  mc::cli::add_format_option(*ev_cmd, *evaluate);
  ev_cmd->callback([evaluate] { run_evaluate(*evaluate); });
  auto tweezers = std::make_shared<TweezersCmd>();
  auto* cmd = add_verb(group, "tweezers", "Optical-tweezers recording replayed on the interface (§3.5.2)",
                       tweezers->common);
  mc::cli::add_format_option(*cmd, tweezers->common);
  cmd->add_option("--scenario", tweezers->scenario, "brownian or contact")
      ->check(CLI::IsMember({"brownian", "contact"}));
  cmd->add_option("--duration", tweezers->duration_s, "Recording length (s)")
      ->check(mc::cli::Range(0.5, 60.0));
  cmd->callback([tweezers] { run_tweezers(*tweezers); });
}

const bool kRegistered = mc::cli::register_group(
    {"haptics", "Dual-stage haptic interface: identify, evaluate, optical tweezers (ch. 3)", 40,
     &add_haptics});

}  // namespace
}  // namespace haptics_commands
