// `microcobot tweezers ...`: the TéléTweez model (ch. 4): parameters, bandwidth identification,
// virtual cube with/without the lag compensator, robotic and manual modes; and the report part.

#include <cmath>
#include <memory>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/core/params.h"
#include "microcobot/studies/tweezers_figures.h"
#include "microcobot/tweezers/config.h"

namespace tweezers_commands {
namespace {

namespace tw = mc::tweezers;
using mc::cli::CommonOptions;
using mc::report::Axis;
using mc::report::Figure;
using mc::report::Report;

tw::TweezersConfig load(const CommonOptions& o) {
  if (o.params) return mc::load_params<tw::TweezersConfig>(*o.params);
  tw::TweezersConfig c;
  c.validate();
  return c;
}

std::vector<double> db(const std::vector<double>& m) {
  std::vector<double> out(m.size());
  for (std::size_t i = 0; i < m.size(); ++i) out[i] = 20 * std::log10(std::max(m[i], 1e-300));
  return out;
}

// ---- identify ---------------------------------------------------------------------------
void run_identify(const CommonOptions& o) {
  const auto cfg = load(o);
  const auto r = tw::identify_bandwidth(cfg.model, cfg.identify);
  const nlohmann::json j{{"mode_Hz", r.features.mode_Hz},
                         {"antiresonance_Hz", r.features.antiresonance_Hz},
                         {"bandwidth_Hz", r.features.bandwidth_Hz}};
  if (o.out) {
    mc::CsvTable t;
    t.add_column("f_Hz", r.f_Hz);
    t.add_column("magnitude_dB", db(r.magnitude));
    t.add_column("phase_rad", r.phase_rad);
    t.add_column("coherence", r.coherence);
    t.add_column("model_magnitude_dB", db(r.model_magnitude));
    mc::cli::write_result_table(o, "frf.csv", t, j);
    Report rep("tweezers identify");
    mc::studies::identify_section(rep, r);
    mc::cli::write_report_if_requested(o, rep);
  }
  mc::cli::emit(
      o, j,
      fmt::format(
          "dominant mode {:.1f} Hz\nantiresonance {:.1f} Hz\nflat band (+-{} dB from {} Hz) up to {:.1f} Hz",
          r.features.mode_Hz, r.features.antiresonance_Hz, cfg.identify.flatness_dB, cfg.identify.band_low_Hz,
          r.features.bandwidth_Hz));
}

// ---- virtual cube -------------------------------------------------------------------------
struct CubeOptions {
  CommonOptions common;
  std::optional<double> stiffness;
  std::optional<double> rate;
  bool no_comp = false;
  bool sweep = false;
};

void run_cube(const CubeOptions& co) {
  auto cfg = load(co.common);
  if (co.stiffness) cfg.cube.stiffness_N_per_m = *co.stiffness;
  if (co.rate) cfg.cube.control_rate_Hz = *co.rate;
  if (co.rate && std::fmod(cfg.cube.plant_rate_Hz, *co.rate) != 0) cfg.cube.plant_rate_Hz = 20.0 * *co.rate;
  cfg.cube.compensator = !co.no_comp;
  if (co.rate) mc::cli::naming_flags({{"control_rate_Hz", "--rate"}}, [&] { cfg.cube.validate(); });
  if (co.sweep) {
    auto c = cfg.cube;
    c.compensator = false;
    const double bare = tw::max_chatter_free_stiffness(cfg.model, c, 100, 1e6);
    c.compensator = true;
    const double comp = tw::max_chatter_free_stiffness(cfg.model, c, 100, 1e6);
    const double bound = tw::colgate_stiffness_bound(cfg.model, c.control_rate_Hz);
    nlohmann::json j{{"max_stiffness_N_m", {{"compensated", comp}, {"uncompensated", bare}}},
                     {"passivity_bound_N_m", bound},
                     {"tip_damping_N_s_m", tw::tip_damping(cfg.model)},
                     {"control_rate_Hz", c.control_rate_Hz}};
    mc::cli::write_results_mat(co.common, j);  // --format mat: the figures; CSV: no table to write
    mc::cli::emit(
        co.common, j,
        fmt::format("largest chatter-free stiffness at {:.0f} Hz: {:.0f} N/m without, {:.0f} N/m with the "
                    "lag compensator (x{:.2f})\nColgate's passivity bound b > KT/2: K < {:.0f} N/m (b = "
                    "{:.2f} N s/m)",
                    c.control_rate_Hz, bare, comp, comp / bare, bound, tw::tip_damping(cfg.model)));
    return;
  }
  // A limit met by a flag's value is named by the flag.
  std::vector<std::pair<std::string, std::string>> flags;
  if (co.stiffness) flags.emplace_back("stiffness_N_per_m", "--stiffness");
  if (co.rate) flags.emplace_back("control_rate_Hz", "--rate");
  tw::VirtualCubeResult r;
  mc::cli::naming_flags(flags, [&] { r = tw::simulate_virtual_cube(cfg.model, cfg.cube); });
  const nlohmann::json j{{"chatter", r.chatter},
                         {"max_penetration_m", r.max_penetration_m},
                         {"oscillation_rms_N", r.oscillation_rms_N},
                         {"mean_force_N", r.mean_force_N}};
  if (co.common.out) {
    mc::CsvTable t;
    t.add_column("t_s", r.t_s);
    t.add_column("tip_opening_m", r.opening_m);
    t.add_column("penetration_m", r.penetration_m);
    t.add_column("wall_force_N", r.wall_force_N);
    t.add_column("torque_N_m", r.torque_N_m);
    mc::cli::write_result_table(co.common, "virtual_cube.csv", t, j);
    Report rep("tweezers virtual-cube");
    rep.section("Virtual cube", "");
    rep.add_figure({"Wall force",
                    "",
                    Axis{"Time", "s", false},
                    Axis{"Wall force", "N", false},
                    {{"wall force", r.t_s, r.wall_force_N, false}}});
    mc::cli::write_report_if_requested(co.common, rep);
  }
  mc::cli::emit(co.common, j,
                fmt::format("K = {:.0f} N/m, {} compensator, {:.0f} Hz loop: {}\nmax penetration {:.3g} m, "
                            "hold force {:.3f} N, "
                            "oscillation rms {:.3g} N",
                            cfg.cube.stiffness_N_per_m, cfg.cube.compensator ? "lag" : "no",
                            cfg.cube.control_rate_Hz, r.chatter ? "CHATTER" : "stable", r.max_penetration_m,
                            r.mean_force_N, r.oscillation_rms_N));
}

// ---- modes ----------------------------------------------------------------------------------
mc::CsvTable trace_table(const tw::ModeTrace& tr) {
  mc::CsvTable t;
  t.add_column("t_s", tr.t_s);
  t.add_column("tip_opening_m", tr.master_opening_m);
  t.add_column("slave_opening_m", tr.slave_opening_m);
  t.add_column("contact_force_N", tr.contact_force_N);
  t.add_column("finger_force_N", tr.finger_force_N);
  t.add_column("torque_N_m", tr.torque_N_m);
  return t;
}

void run_robotic(const CommonOptions& o) {
  const auto cfg = load(o);
  const auto r = tw::simulate_robotic_mode(cfg.model, cfg.robotic);
  const nlohmann::json j{{"slave_force_N", r.final_slave_force_N},
                         {"finger_force_N", r.final_rendered_force_N},
                         {"slave_opening_m", r.trace.slave_opening_m.back()},
                         {"tip_opening_m", r.trace.master_opening_m.back()}};
  if (o.out) {
    mc::cli::write_result_table(o, "robotic.csv", trace_table(r.trace), j);
    Report rep("tweezers robotic");
    mc::studies::robotic_section(rep, r, cfg.robotic);
    mc::cli::write_report_if_requested(o, rep);
  }
  mc::cli::emit(o, j);
}

void run_manual(const CommonOptions& o, bool no_hold) {
  auto cfg = load(o);
  if (no_hold) cfg.manual.hold = false;
  const auto r = tw::simulate_manual_mode(cfg.model, cfg.manual);
  const nlohmann::json j{{"held_force_N", r.held_force_N},
                         {"held_force_error_N", r.held_force_error_N},
                         {"set_force_N", cfg.manual.set_force_N}};
  if (o.out) {
    mc::cli::write_result_table(o, "manual.csv", trace_table(r.trace), j);
    auto plain = cfg.manual;
    plain.hold = false;
    Report rep("tweezers manual");
    mc::studies::manual_section(rep, r, tw::simulate_manual_mode(cfg.model, plain), cfg.manual);
    mc::cli::write_report_if_requested(o, rep);
  }
  mc::cli::emit(o, j);
}

void add_tweezers(CLI::App& group) {
  group.require_subcommand(1);
  {
    auto o = std::make_shared<CommonOptions>();
    auto* cmd = group.add_subcommand("params", "Print the default parameters (the keys --params accepts)");
    mc::cli::add_output_options(*cmd, *o);
    mc::cli::add_params_option(*cmd, *o);
    cmd->callback([o] { mc::cli::emit(*o, mc::params_to_json(load(*o)), mc::params_to_yaml(load(*o))); });
  }
  {
    auto o = std::make_shared<CommonOptions>();
    auto* cmd = group.add_subcommand("identify", "PRBS bandwidth identification at 10 kHz (section 4.5.2)");
    mc::cli::add_output_options(*cmd, *o);
    mc::cli::add_format_option(*cmd, *o);
    mc::cli::add_params_option(*cmd, *o);
    cmd->callback([o] { run_identify(*o); });
  }
  {
    auto o = std::make_shared<CubeOptions>();
    auto* cmd = group.add_subcommand("virtual-cube",
                                     "Virtual cube between the tips: chatter and lag compensator (4.5.3)");
    mc::cli::add_output_options(*cmd, o->common);
    mc::cli::add_format_option(*cmd, o->common);
    mc::cli::add_params_option(*cmd, o->common);
    cmd->add_option("--stiffness", o->stiffness, "Wall stiffness per tip [N/m]")
        ->check(mc::cli::PositiveNumber);
    cmd->add_option("--rate", o->rate, "Controller rate [Hz] (default 1000)")->check(mc::cli::PositiveNumber);
    cmd->add_flag("--no-compensator", o->no_comp, "Render the bare spring (no lag compensator)");
    cmd->add_flag("--sweep", o->sweep, "Largest chatter-free stiffness with and without the compensator");
    cmd->callback([o] { run_cube(*o); });
  }
  {
    auto o = std::make_shared<CommonOptions>();
    auto* cmd =
        group.add_subcommand("robotic", "Robotic mode: opening to a slave gripper, its force back (4.3.2.1)");
    mc::cli::add_output_options(*cmd, *o);
    mc::cli::add_format_option(*cmd, *o);
    mc::cli::add_params_option(*cmd, *o);
    cmd->callback([o] { run_robotic(*o); });
  }
  {
    auto o = std::make_shared<CommonOptions>();
    auto no_hold = std::make_shared<bool>(false);
    auto* cmd =
        group.add_subcommand("manual", "Manual mode: hold a set clamping force on a real object (4.3.2.2)");
    mc::cli::add_output_options(*cmd, *o);
    mc::cli::add_format_option(*cmd, *o);
    mc::cli::add_params_option(*cmd, *o);
    cmd->add_flag("--no-hold", *no_hold, "Plain tweezers: no force loop");
    cmd->callback([o, no_hold] { run_manual(*o, *no_hold); });
  }
}

const bool kRegistered = mc::cli::register_group(
    {"tweezers", "TéléTweez haptic tweezers: identification, virtual cube, control modes (ch. 4)", 70,
     &add_tweezers});

}  // namespace
}  // namespace tweezers_commands
