// `microcobot identify ...`: identification of a stick-slip axis from measured data (thesis
// §2.5.2). Each command writes the identified parameter file (the keys of
// `stickslip params`), a report section with the fit plots (--out DIR) and --json.

#include <chrono>
#include <cmath>
#include <memory>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include "cli.h"
#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/core/params.h"
#include "microcobot/stickslip/ident_all.h"
#include "microcobot/stickslip/ident_synthetic.h"
#include "microcobot/studies/identification_figures.h"

namespace identify_commands {
namespace {

namespace ss = mc::stickslip;
using mc::cli::CommonOptions;
using nlohmann::json;

struct Opts {
  CommonOptions common;
  std::string in;
  std::string save;
  int operators = 35;
  unsigned threads = 0;
  std::string grid = "small";
  std::uint64_t seed = 1;
  double voltage_noise_V = -1.0;   ///< synth: RMS voltage noise [V] (< 0: 1 % of each drive's amplitude)
  double position_noise_m = 1e-9;  ///< synth: RMS position noise [m]
};

ss::StickSlipParams base_params(const CommonOptions& o) {
  return o.params ? mc::load_params<ss::StickSlipParams>(*o.params) : ss::StickSlipParams{};
}

/// --save must not replace what the command reads (data loss): the --in file itself, or a
/// measurement (.csv, .mat) of an --in directory. Checked before any work.
void refuse_save_onto_input(const Opts& o) {
  if (o.save.empty()) return;
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path save(o.save), in(o.in);
  if (fs::is_directory(save, ec))
    throw mc::UsageError("--save '" + mc::excerpt(o.save) + "' is a directory: name the YAML file to write");
  if (fs::equivalent(save, in, ec)) {
    throw mc::UsageError("--save '" + o.save +
                         "' is the --in file: writing the parameters there would replace the measurement");
  }
  const fs::path dir = save.has_parent_path() ? save.parent_path() : fs::path(".");
  const std::string ext = save.extension().string();
  if (fs::is_directory(in, ec) && fs::exists(save, ec) && fs::equivalent(dir, in, ec) &&
      (ext == ".csv" || ext == ".mat")) {
    throw mc::UsageError("--save '" + o.save +
                         "' is a measurement in the --in directory: writing the parameters there would "
                         "replace it");
  }
}

/// Writes the identified parameters to --save FILE and/or DIR/params.yaml; returns the paths.
json save_params(const Opts& o, const ss::StickSlipParams& p) {
  json files = json::array();
  const std::string yaml =
      "# identified by microcobot identify (thesis section 2.5.2)\n" + mc::params_to_yaml(p);
  if (!o.save.empty()) {
    mc::write_file_atomic(o.save, yaml);
    files.push_back(o.save);
  }
  if (o.common.out) {
    mc::ensure_writable_dir(*o.common.out);
    mc::write_file_atomic(*o.common.out / "params.yaml", yaml);
    files.push_back((*o.common.out / "params.yaml").string());
  }
  return files;
}

json mode_json(const ss::ModeEstimate& m) {
  return {{"frequency_Hz", m.frequency_Hz}, {"damping_ratio", m.damping_ratio}};
}

json runs_json(const ss::BreakawayResult& r) {
  json runs = json::array();
  for (const auto& x : r.runs) {
    json j{{"name", x.name},
           {"amplitude_V", x.amplitude_V},
           {"frequency_Hz", x.frequency_Hz},
           {"direction", ss::to_string(x.direction)},
           {"ok", x.ok},
           {"v_measured_m_s", x.v_measured_m_s},
           {"simulations", x.simulations}};
    if (x.ok) {
      j["z_ba_m"] = x.z_ba_m;
      j["v_simulated_m_s"] = x.v_simulated_m_s;
    } else {
      j["skipped"] = x.skipped;
    }
    runs.push_back(j);
  }
  return runs;
}

json pe_json(const ss::PeModesResult& r) {
  return {{"mode_a", mode_json(r.a)},
          {"mode_b", mode_json(r.b)},
          {"gain_fraction_a", r.gain_fraction_a},
          {"static_gain_m_V", r.static_gain_m_V},
          {"psd_peaks_Hz", r.psd_peaks_Hz},
          {"rms_m", r.rms_m},
          {"step_V", r.step_V}};
}
json friction_json(const ss::FrictionModesResult& r) {
  return {{"mode_a", mode_json(r.a)},
          {"mode_b", mode_json(r.b)},
          {"rho0_a_N_m", r.params.rho0_a_N_m},
          {"rho1_a_N_s_m", r.params.rho1_a_N_s_m},
          {"rho0_b_N_m", r.params.rho0_b_N_m},
          {"rho1_b_N_s_m", r.params.rho1_b_N_s_m},
          {"mass_fraction_a", r.mass_fraction_a},
          {"psd_peaks_Hz", r.psd_peaks_Hz},
          {"rms_m", r.rms_m}};
}
json hysteresis_json(const ss::HysteresisResult& r) {
  return {
      {"thresholds_V", r.pi.thresholds_V},
      {"weights", r.pi.weights},
      {"static_gain_m_V", r.static_gain_m_V},
      {"rms_m", r.rms_m},
      {"stroke_m", r.stroke_m},
      {"rms_fraction_of_stroke", r.rms_fraction},
      {"inverse", {{"thresholds_V", r.inverse.thresholds_V}, {"weights", r.inverse.weights}}},
      {"inverse_max_error_V", r.inverse_max_error_V},
      {"from_rest", r.from_rest},
      {"rms_from_rest_m", std::isfinite(r.rms_from_rest_m) ? json(r.rms_from_rest_m) : json(nullptr)},
      {"rms_steady_loop_m", std::isfinite(r.rms_steady_loop_m) ? json(r.rms_steady_loop_m) : json(nullptr)},
      {"voltage_noise_V", r.voltage_noise_V}};
}

void finish(const Opts& o, const std::string& title, const ss::StickSlipParams& p, json j,
            const mc::report::Report& rep, const std::string& human) {
  j["params_files"] = save_params(o, p);
  // --format mat: results.mat holds every number of the summary (e.g. mode_a_frequency_Hz).
  mc::cli::write_results_mat(o.common, j);
  mc::cli::write_report_if_requested(o.common, rep);
  (void)title;
  mc::cli::emit(o.common, j, human);
}

void progress_cb(const std::string& task, std::size_t d, std::size_t t) { mc::cli::progress(task, d, t); }

CLI::App* command(CLI::App& group, const std::string& name, const std::string& help, std::shared_ptr<Opts> o,
                  const std::string& in_help) {
  auto* cmd = group.add_subcommand(name, help);
  cmd->add_option("--in", o->in, in_help)->required();
  cmd->add_option("--save", o->save, "Also write the identified parameter file here (YAML)");
  mc::cli::add_params_option(*cmd, o->common);
  mc::cli::add_output_options(*cmd, o->common);
  mc::cli::add_format_option(*cmd, o->common);
  return cmd;
}

void add_identify(CLI::App& group) {
  group.require_subcommand(1);
  {
    auto o = std::make_shared<Opts>();
    command(group, "pe-modes",
            "PE modes (frequency, damping, gain split) from a step of the PE without slider", o,
            "CSV t_s,u_V,x_m or .mat with t, u, x (SI): PE step response (~1 MHz)")
        ->callback([o] {
          refuse_save_onto_input(*o);
          const auto base = base_params(o->common);
          const auto rec = ss::read_record(o->in);
          const auto r = ss::identify_pe_modes(rec, base.pe);
          auto p = base;
          p.pe = r.params;
          mc::report::Report rep("identify pe-modes");
          mc::studies::pe_section(rep, rec, r);
          finish(*o, "pe-modes", p, pe_json(r), rep,
                 fmt::format(
                     "PE modes: {:.5g} Hz (zeta {:.4f}), {:.5g} Hz (zeta {:.4f}); gain split phi = {:.3f}",
                     r.a.frequency_Hz, r.a.damping_ratio, r.b.frequency_Hz, r.b.damping_ratio,
                     r.gain_fraction_a));
        });
  }
  {
    auto o = std::make_shared<Opts>();
    command(group, "friction-modes",
            "The two asperities (rho0, rho1 each) from a scanning-mode step response", o,
            "CSV t_s,u_V,x_m or .mat with t, u, x (SI): actuator step response (~25 kHz)")
        ->callback([o] {
          refuse_save_onto_input(*o);
          const auto base = base_params(o->common);
          const auto rec = ss::read_record(o->in);
          const auto r = ss::identify_friction_modes(rec, base);
          auto p = base;
          p.friction = r.params;
          mc::report::Report rep("identify friction-modes");
          mc::studies::friction_section(rep, rec, r);
          finish(*o, "friction-modes", p, friction_json(r), rep,
                 fmt::format("asperity modes: {:.5g} Hz (zeta {:.3f}), {:.5g} Hz (zeta {:.3f}); c_a = {:.3f}",
                             r.a.frequency_Hz, r.a.damping_ratio, r.b.frequency_Hz, r.b.damping_ratio,
                             r.mass_fraction_a));
        });
  }
  {
    auto o = std::make_shared<Opts>();
    auto* cmd =
        command(group, "hysteresis", "PI thresholds and weights (NNLS) and the inverse from a sine response",
                o, "CSV t_s,u_V,x_m or .mat with t, u, x (SI): slider response to a sine (scanning mode)");
    cmd->add_option("--operators", o->operators, "Number of play operators (thesis: 35)")
        ->check(mc::cli::Range(1, 200));
    cmd->callback([o] {
      refuse_save_onto_input(*o);
      auto base = base_params(o->common);
      const auto rec = ss::read_record(o->in);
      const auto r = ss::identify_hysteresis(rec, o->operators, o->common.params ? &base : nullptr);
      base.hysteresis = r.pi;
      base.pe.static_gain_m_V = r.static_gain_m_V;
      mc::report::Report rep("identify hysteresis");
      mc::studies::hysteresis_section(rep, rec, r);
      finish(*o, "hysteresis", base, hysteresis_json(r), rep,
             fmt::format(
                 "PI model: {} operators, g = {:.4g} m/V, loop RMS error {:.3g} m = {:.2f}% of the stroke",
                 r.pi.size(), r.static_gain_m_V, r.rms_m, 100 * r.rms_fraction));
    });
  }
  {
    auto o = std::make_shared<Opts>();
    auto* cmd = command(group, "breakaway", "z_ba of each sawtooth run and the surface z_ba(A, f, direction)",
                        o, "Directory of sawtooth_<A>V_<f>Hz_<forward|backward>.csv runs");
    cmd->add_option("--threads", o->threads, "Worker threads (default: all cores)")
        ->check(mc::cli::Range(1, 64));
    cmd->callback([o] {
      refuse_save_onto_input(*o);
      auto base = base_params(o->common);
      const auto runs = ss::read_sawtooth_runs(o->in);
      const ss::ActuatorModel model(base);
      ss::BreakawayOptions bo;
      bo.threads = o->threads;
      const auto r = ss::identify_breakaway(runs, model, bo, [](std::size_t d, std::size_t t) {
        progress_cb("identify breakaway (runs)", d, t);
      });
      base.breakaway = r.table;
      mc::report::Report rep("identify breakaway");
      mc::studies::breakaway_section(rep, r);
      json j{{"runs", runs_json(r)},
             {"skipped", r.skipped},
             {"filled_cells", r.filled},
             {"extrapolated_cells", r.extrapolated}};
      finish(*o, "breakaway", base, j, rep,
             fmt::format("z_ba identified for {} of {} runs ({} skipped)", r.runs.size() - r.skipped,
                         r.runs.size(), r.skipped));
    });
  }
  {
    auto o = std::make_shared<Opts>();
    auto* cmd = command(group, "all", "The three steps of section 2.5.2 in order, one parameter file", o,
                        "Directory with pe_step.csv (optional), step.csv, sine.csv, sawtooth_*.csv");
    cmd->add_option("--operators", o->operators, "Number of play operators (thesis: 35)")
        ->check(mc::cli::Range(1, 200));
    cmd->add_option("--threads", o->threads, "Worker threads (default: all cores)")
        ->check(mc::cli::Range(1, 64));
    cmd->callback([o] {
      refuse_save_onto_input(*o);
      const auto base = base_params(o->common);
      ss::IdentifyAllOptions io;
      io.operators = o->operators;
      io.breakaway.threads = o->threads;
      const auto t0 = std::chrono::steady_clock::now();
      const auto r = ss::identify_all(o->in, base, io, progress_cb);
      const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      mc::report::Report rep("identify all");
      const std::filesystem::path dir(o->in);
      if (r.pe) mc::studies::pe_section(rep, ss::read_record(dir / "pe_step.csv"), *r.pe);
      mc::studies::friction_section(rep, ss::read_record(dir / "step.csv"), r.friction);
      mc::studies::hysteresis_section(rep, ss::read_record(dir / "sine.csv"), r.hysteresis);
      mc::studies::breakaway_section(rep, r.breakaway);
      json j{{"friction_modes", friction_json(r.friction)},
             {"hysteresis", hysteresis_json(r.hysteresis)},
             {"breakaway",
              {{"runs", runs_json(r.breakaway)},
               {"skipped", r.breakaway.skipped},
               {"filled_cells", r.breakaway.filled},
               {"extrapolated_cells", r.breakaway.extrapolated}}},
             {"notes", r.notes},
             {"elapsed_s", secs}};
      if (r.pe) j["pe_modes"] = pe_json(*r.pe);
      finish(*o, "all", r.params, j, rep,
             fmt::format(
                 "identified in {:.1f} s: PE {}, asperities {:.4g}/{:.4g} Hz, PI loop error {:.2f}% of the "
                 "stroke, z_ba for {} of {} runs\n{}",
                 secs,
                 r.pe ? fmt::format("{:.4g}/{:.4g} Hz", r.pe->a.frequency_Hz, r.pe->b.frequency_Hz)
                      : std::string("kept"),
                 r.friction.a.frequency_Hz, r.friction.b.frequency_Hz, 100 * r.hysteresis.rms_fraction,
                 r.breakaway.runs.size() - r.breakaway.skipped, r.breakaway.runs.size(),
                 fmt::format("{}", fmt::join(r.notes, "\n"))));
    });
  }
  {
    auto o = std::make_shared<Opts>();
    auto* cmd = group.add_subcommand(
        "synth", "Write a synthetic measurement campaign (simulated axis + sensor effects) for identify all");
    cmd->add_option("--grid", o->grid,
                    "small (4x3x2 runs) or full (10 amplitudes x 5 frequencies x 2 directions)")
        ->check(CLI::IsMember({"small", "full"}));
    cmd->add_option("--seed", o->seed, "Noise seed");
    cmd->add_option("--voltage-noise", o->voltage_noise_V,
                    "RMS noise on the recorded voltage [V] (default: 1 % of each drive's amplitude)")
        ->check(CLI::Range(0.0, 10.0));
    cmd->add_option("--position-noise", o->position_noise_m,
                    "RMS noise on the recorded position [m] (default 1e-9)")
        ->check(CLI::Range(0.0, 1e-6));
    mc::cli::add_params_option(*cmd, o->common);
    cmd->add_flag("--json", o->common.json, "Print a machine-readable JSON summary on stdout");
    cmd->add_option("--out", o->common.out, "Directory to write the campaign to")->required();
    cmd->callback([o] {
      const auto truth = base_params(o->common);
      ss::CampaignPlan plan;
      if (o->grid == "full") {
        plan.amplitudes_V = {10, 20, 30, 40, 50, 60, 70, 80, 90, 100};
        plan.frequencies_Hz = {50, 100, 500, 1000, 2000};
      }
      ss::SensorEffects sensor;
      sensor.seed = o->seed;
      sensor.voltage_noise_rms_V = o->voltage_noise_V;
      sensor.position_noise_rms_m = o->position_noise_m;
      const std::size_t n = ss::write_campaign(
          *o->common.out, truth, plan, sensor,
          [](std::size_t d, std::size_t t) { progress_cb("identify synth (sawtooth runs)", d, t); });
      mc::write_file_atomic(*o->common.out / "truth.yaml", mc::params_to_yaml(truth));
      mc::cli::emit(o->common, {{"files", n}, {"dir", o->common.out->string()}},
                    fmt::format("{} measurement files written to {}", n, o->common.out->string()));
    });
  }
}

const bool kRegistered = mc::cli::register_group(
    {"identify", "Identify a stick-slip axis from measured data (thesis 2.5)", 35, &add_identify});

}  // namespace
}  // namespace identify_commands
