// `microcobot tweezers ...`: the TéléTweez model (ch. 4): parameters, bandwidth identification,
// virtual cube with/without the lag compensator, robotic and manual modes; and the report part.

#include <cmath>
#include <memory>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/core/params.h"
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

std::vector<double> scaled(const std::vector<double>& v, double k) {
  std::vector<double> out(v);
  for (double& x : out) x *= k;
  return out;
}

// ---- identify ---------------------------------------------------------------------------
void identify_section(Report& rep, const tw::BandwidthIdentResult& r) {
  rep.section(
      "TéléTweez bandwidth identification (section 4.5.2)",
      "PRBS motor torque at 10 kHz, finger-contact acceleration (accelerometer, Fig. 4.24), H1 "
      "estimate by Welch averaging, against the analytic FRF of the 7-DOF model. The dominant mode, "
      "the antiresonance of the cantilever tip and the flat band (within +-3 dB, from 20 Hz) are read "
      "off the estimate (thesis Fig. 4.25: 150 Hz, 390 Hz, 100 Hz).");
  rep.add_result("dominant mode", r.features.mode_Hz, "Hz");
  rep.add_result("antiresonance", r.features.antiresonance_Hz, "Hz");
  rep.add_result("flat band upper edge", r.features.bandwidth_Hz, "Hz");
  std::vector<double> f, h, m;
  for (std::size_t i = 0; i < r.f_Hz.size(); ++i) {
    if (r.f_Hz[i] < 2 || r.f_Hz[i] > 2000) continue;
    f.push_back(r.f_Hz[i]);
    h.push_back(20 * std::log10(r.magnitude[i]));
    m.push_back(20 * std::log10(r.model_magnitude[i]));
  }
  const double top = *std::max_element(h.begin(), h.end()), bottom = *std::min_element(h.begin(), h.end());
  rep.add_figure(
      {"TéléTweez FRF: torque to finger acceleration",
       "H1 estimate (PRBS, 10 kHz) and the model's FRF; vertical markers at the identified mode, "
       "antiresonance and flat-band edge.",
       Axis{"Frequency", "Hz", true},
       Axis{"|a/T|", "dB re 1 m/s^2/(N m)", false},
       {{"H1 estimate", f, h, false},
        {"model", f, m, false},
        {"mode", {r.features.mode_Hz, r.features.mode_Hz}, {bottom, top}, false},
        {"antiresonance", {r.features.antiresonance_Hz, r.features.antiresonance_Hz}, {bottom, top}, false},
        {"flat band edge", {r.features.bandwidth_Hz, r.features.bandwidth_Hz}, {bottom, top}, false}}});
}

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
    identify_section(rep, r);
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
Figure cube_figure(const std::string& title, const tw::VirtualCubeResult& bare,
                   const tw::VirtualCubeResult& comp, double k) {
  return {
      title,
      fmt::format("Rendered wall force per tip, K = {:.0f} N/m, without and with the lag compensator.", k),
      Axis{"Time", "s", false},
      Axis{"Wall force", "N", false},
      {{"no compensator", bare.t_s, bare.wall_force_N, false},
       {"lag compensator", comp.t_s, comp.wall_force_N, false}}};
}

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

void robotic_section(Report& rep, const tw::RoboticModeResult& r, const tw::RoboticModeParams& p) {
  rep.section(
      "Robotic control mode (section 4.3.2.1)",
      fmt::format(
          "The operator pinches; the slave gripper's opening follows the tips' opening scaled by {} and "
          "closes on a {:.0f} um object; its contact force, scaled by {:.0f}, is rendered at the fingers.",
          p.position_scale, p.object_width_m * 1e6, p.force_scale));
  rep.add_result("slave contact force", r.final_slave_force_N * 1e6, "uN");
  rep.add_result("rendered finger force", r.final_rendered_force_N, "N");
  rep.add_figure({"Robotic mode: openings",
                  "Tweezers tip opening (mm) and slave opening (um).",
                  Axis{"Time", "s", false},
                  Axis{"Opening", "mm / um", false},
                  {{"tweezers tips [mm]", r.trace.t_s, scaled(r.trace.master_opening_m, 1e3), false},
                   {"slave jaws [um]", r.trace.t_s, scaled(r.trace.slave_opening_m, 1e6), false}}});
  rep.add_figure({"Robotic mode: forces",
                  "Slave contact force (uN) and force rendered at each finger (mN).",
                  Axis{"Time", "s", false},
                  Axis{"Force", "uN / mN", false},
                  {{"slave contact [uN]", r.trace.t_s, scaled(r.trace.contact_force_N, 1e6), false},
                   {"finger [mN]", r.trace.t_s, scaled(r.trace.finger_force_N, 1e3), false}}});
}

void manual_section(Report& rep, const tw::ManualModeResult& hold, const tw::ManualModeResult& plain,
                    const tw::ManualModeParams& p) {
  rep.section(
      "Manual control mode (section 4.3.2.2)",
      fmt::format("The operator grasps a {:.0f} mm object, then relaxes at {:.1f} s. With the force loop the "
                  "tweezers keep {:.2f} N on it by themselves; a plain tweezers lets it go.",
                  p.object_width_m * 1e3, p.release_s, p.set_force_N));
  rep.add_result("held clamping force", hold.held_force_N, "N");
  rep.add_result("max error after release", hold.held_force_error_N, "N");
  rep.add_figure({"Manual mode: clamping force",
                  "Force on the object, with the force loop and without.",
                  Axis{"Time", "s", false},
                  Axis{"Clamping force", "N", false},
                  {{"force loop", hold.trace.t_s, hold.trace.contact_force_N, false},
                   {"plain tweezers", plain.trace.t_s, plain.trace.contact_force_N, false},
                   {"operator's finger", hold.trace.t_s, hold.trace.finger_force_N, false}}});
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
    robotic_section(rep, r, cfg.robotic);
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
    manual_section(rep, r, tw::simulate_manual_mode(cfg.model, plain), cfg.manual);
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

void tweezers_part(Report& rep) {
  const tw::TweezersConfig cfg;
  identify_section(rep, tw::identify_bandwidth(cfg.model, cfg.identify));
  // Virtual cube: a stiff wall with and without the compensator, and the sweep.
  auto c = cfg.cube;
  c.stiffness_N_per_m = 16000;
  c.compensator = false;
  const auto bare = tw::simulate_virtual_cube(cfg.model, c);
  c.compensator = true;
  const auto comp = tw::simulate_virtual_cube(cfg.model, c);
  auto s = cfg.cube;
  s.compensator = false;
  const double kb = tw::max_chatter_free_stiffness(cfg.model, s, 100, 1e6, 10);
  s.compensator = true;
  const double kc = tw::max_chatter_free_stiffness(cfg.model, s, 100, 1e6, 10);
  rep.section(
      "Virtual cube without chatter (section 4.5.3)",
      fmt::format(
          "A {:.0f} mm cube between the tips rendered as a spring by a {:.0f} Hz sampled controller "
          "(ZOH) reading the lever strain gauges; lag compensator pole {:.0f} Hz, zero {:.0f} Hz. "
          "Chatter: oscillation rms above {:.0f} % of the mean force, or contact lost, in the last {:.1f} s.",
          cfg.cube.cube_width_m * 1e3, cfg.cube.control_rate_Hz, cfg.cube.lag_pole_Hz, cfg.cube.lag_zero_Hz,
          cfg.cube.chatter_rel_rms * 100, cfg.cube.hold_window_s));
  rep.add_result("max chatter-free stiffness, no compensator", kb, "N/m");
  rep.add_result("max chatter-free stiffness, lag compensator", kc, "N/m");
  rep.add_result("Colgate passivity bound 2b/T",
                 tw::colgate_stiffness_bound(cfg.model, cfg.cube.control_rate_Hz), "N/m");
  rep.add_figure(cube_figure("Virtual cube: wall force at 16 kN/m", bare, comp, 16000));
  robotic_section(rep, tw::simulate_robotic_mode(cfg.model, cfg.robotic), cfg.robotic);
  auto plain = cfg.manual;
  plain.hold = false;
  manual_section(rep, tw::simulate_manual_mode(cfg.model, cfg.manual),
                 tw::simulate_manual_mode(cfg.model, plain), cfg.manual);
}

const bool kRegistered = mc::cli::register_group(
    {"tweezers", "TéléTweez haptic tweezers: identification, virtual cube, control modes (ch. 4)", 70,
     &add_tweezers});
const bool kPart = mc::cli::register_report_part({"tweezers", 70, &tweezers_part});

}  // namespace
}  // namespace tweezers_commands
