// `microcobot design ...`: the TéléTweez design calculators (thesis ch. 4, app. A, B, eq. 3.2).
// Every figure is computed from the flags; nothing is typed in.

#include <cmath>
#include <memory>
#include <numbers>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/core/error.h"
#include "microcobot/tweezers/actuator_options.h"
#include "microcobot/tweezers/amplifier.h"
#include "microcobot/tweezers/ballscrew.h"
#include "microcobot/tweezers/beam.h"
#include "microcobot/tweezers/piezo_brake.h"
#include "microcobot/tweezers/specs.h"
#include "microcobot/tweezers/transmission.h"

namespace design_commands {
namespace {

namespace tw = mc::tweezers;
using mc::cli::CommonOptions;

/// Flags of one calculator: named doubles plus the common output options.
struct Calc {
  CommonOptions common;
  double v[6] = {0, 0, 0, 0, 0, 0};
  std::string text;
  bool has[6] = {false, false, false, false, false, false};
};

CLI::Option* number(CLI::App* cmd, const std::string& flag, double& value, const std::string& help,
                    bool required = true, const CLI::Validator& check = mc::cli::PositiveNumber) {
  auto* opt = cmd->add_option(flag, value, help)->check(check);
  if (required) opt->required();
  return opt;
}

void add_ballscrew(CLI::App& group) {
  auto c = std::make_shared<Calc>();
  auto* cmd = group.add_subcommand("ballscrew",
                                   "Lead angle and forward/backward efficiency of a ball screw (app. B)");
  number(cmd, "--diameter", c->v[0], "Nominal diameter d [m]");
  number(cmd, "--lead", c->v[1], "Lead p per turn [m]");
  number(cmd, "--mu", c->v[2], "Friction coefficient mu (mu = tan phi)", true, mc::cli::NonNegativeNumber);
  mc::cli::add_output_options(*cmd, c->common);
  cmd->callback([c] {
    tw::BallScrewEfficiency e;
    mc::cli::naming_flags({{"diameter_m", "--diameter"}, {"lead_m", "--lead"}, {"mu", "--mu"}},
                          [&] { e = tw::ball_screw_efficiency(c->v[0], c->v[1], c->v[2]); });
    nlohmann::json j{{"lead_angle_rad", e.lead_angle_rad},
                     {"forward_efficiency", e.forward_efficiency},
                     {"backward_efficiency", e.backward_efficiency}};
    mc::cli::emit(c->common, j,
                  fmt::format("lead angle {:.4f} rad ({:.2f} deg)\nforward efficiency  (eq. B.6) {:.3f}\n"
                              "backward efficiency (eq. B.9) {:.3f}",
                              e.lead_angle_rad, e.lead_angle_rad * 180 / std::numbers::pi,
                              e.forward_efficiency, e.backward_efficiency));
  });
}

void add_actuator(CLI::App& group) {
  auto c = std::make_shared<Calc>();
  auto* cmd = group.add_subcommand("actuator", "Axial force of the ball screw driven by the motor (eq. 4.4)");
  number(cmd, "--torque", c->v[0], "Motor torque C [N m]");
  number(cmd, "--lead", c->v[1], "Lead p [m]");
  number(cmd, "--efficiency", c->v[2], "Forward efficiency eta_f", true, mc::cli::Range(0.0, 1.0));
  mc::cli::add_output_options(*cmd, c->common);
  cmd->callback([c] {
    const double f = tw::axial_force(c->v[0], c->v[1], c->v[2]);
    mc::cli::emit(c->common, {{"axial_force_N", f}}, fmt::format("axial force (eq. 4.4) {:.3f} N", f));
  });
}

void add_transmission(CLI::App& group) {
  auto c = std::make_shared<Calc>();
  c->v[3] = tw::TweezersSpecs{}.min_force_N();
  auto* cmd =
      group.add_subcommand("transmission", "Finger force (eq. 4.5) and magnetic preload (section 4.4.2)");
  number(cmd, "--alpha", c->v[0], "Contact angle alpha [deg]", true, mc::cli::Range(0.0, 90.0));
  number(cmd, "--eta", c->v[1], "Transmission efficiency eta_t", true, mc::cli::Range(0.0, 1.0));
  number(cmd, "--axial-force", c->v[2], "Axial force of the ball screw F_a [N]", true,
         mc::cli::NonNegativeNumber);
  number(cmd, "--closing-force", c->v[3], "Finger force to pull while closing [N] (default: eq. 4.1)", false,
         mc::cli::NonNegativeNumber);
  mc::cli::add_output_options(*cmd, c->common);
  cmd->callback([c] {
    if (c->v[0] <= 0 || c->v[0] >= 90) throw mc::UsageError("--alpha: must be in (0, 90) deg");
    if (c->v[1] <= 0) throw mc::UsageError("--eta: must be in (0, 1]");
    const double alpha = c->v[0] * std::numbers::pi / 180.0;
    const double fy = tw::finger_force(c->v[2], alpha, c->v[1]);
    const double pre = tw::min_preload(c->v[3], alpha);
    mc::cli::emit(
        c->common, {{"finger_force_N", fy}, {"min_preload_N", pre}},
        fmt::format(
            "finger force (eq. 4.5) {:.3f} N\nminimum magnetic preload for {:.2f} N closing: {:.3f} N", fy,
            c->v[3], pre));
  });
}

void add_stiffness_force(CLI::App& group) {
  auto c = std::make_shared<Calc>();
  auto* cmd = group.add_subcommand("stiffness-force", "Force to hold the tweezers closed (eq. 4.1)");
  number(cmd, "--stiffness", c->v[0], "Clamping stiffness at the fingers [N/m]", true,
         mc::cli::NonNegativeNumber);
  number(cmd, "--opening", c->v[1], "Opening to close [m]", true, mc::cli::NonNegativeNumber);
  mc::cli::add_output_options(*cmd, c->common);
  cmd->callback([c] {
    const double f = tw::stiffness_force(c->v[0], c->v[1]);
    mc::cli::emit(c->common, {{"force_N", f}}, fmt::format("minimum actuator force (eq. 4.1) {:.3f} N", f));
  });
}

void add_amplifier(CLI::App& group) {
  auto c = std::make_shared<Calc>();
  auto* cmd =
      group.add_subcommand("amplifier", "Transverse expansion of the piezo amplifier (eq. A.8, Table 4.5)");
  number(cmd, "--length", c->v[0], "Piezo stack length L [m]");
  number(cmd, "--stroke", c->v[1], "Stack stroke dL [m]");
  number(cmd, "--e", c->v[2], "Connection length e [m]", true, mc::cli::NonNegativeNumber);
  number(cmd, "--a", c->v[3], "Amplifier half-height a [m]");
  mc::cli::add_output_options(*cmd, c->common);
  cmd->callback([c] {
    const auto r = tw::amplifier_expansion(c->v[0], c->v[1], c->v[2], c->v[3]);
    mc::cli::emit(c->common, {{"transverse_expansion_m", r.transverse_expansion_m}, {"ratio", r.ratio}},
                  fmt::format("transverse expansion 2 da (eq. A.8) {:.4g} m\nratio 2 da / dL {:.3f}",
                              r.transverse_expansion_m, r.ratio));
  });
}

void add_piezo_brake(CLI::App& group) {
  auto c = std::make_shared<Calc>();
  auto* cmd = group.add_subcommand("piezo-brake", "Blocking force of the piezo friction brake (eq. 4.2-4.3)");
  number(cmd, "--max-force", c->v[0], "Stack maximum push force [N]");
  number(cmd, "--travel-used", c->v[1], "Fraction of the travel spent closing the gap", true,
         mc::cli::Range(0.0, 1.0));
  number(cmd, "--mu", c->v[2], "Friction coefficient plate/stack", true, mc::cli::NonNegativeNumber);
  number(cmd, "--geometry", c->v[3], "Geometry coefficient (friction -> force between tips)", true,
         mc::cli::NonNegativeNumber);
  mc::cli::add_output_options(*cmd, c->common);
  cmd->callback([c] {
    const double f = tw::piezo_block_force(c->v[0], c->v[1], c->v[2], c->v[3]);
    mc::cli::emit(c->common, {{"block_force_N", f}},
                  fmt::format("push force (eq. 4.2) {:.2f} N\nblocking force (eq. 4.3) {:.3f} N",
                              tw::piezo_push_force(c->v[0], c->v[1]), f));
  });
}

void add_beam(CLI::App& group) {
  auto c = std::make_shared<Calc>();
  auto* cmd =
      group.add_subcommand("beam", "First natural frequency of a clamped square beam (eq. 3.2, Table 3.1)");
  auto* mat = cmd->add_option("--material", c->text,
                              "Material of Table 3.1: cast-iron, stainless-steel, aluminum, carbon-fiber");
  auto* young = number(cmd, "--young", c->v[0], "Young's modulus E [Pa]", false);
  auto* density = number(cmd, "--density", c->v[1], "Density rho [kg/m^3]", false);
  mat->excludes(young)->excludes(density);
  young->needs(density);
  density->needs(young);
  number(cmd, "--length", c->v[2], "Beam length L [m]");
  number(cmd, "--side", c->v[3], "Side of the square section [m]");
  mc::cli::add_output_options(*cmd, c->common);
  cmd->callback([c, mat, young] {
    double e = c->v[0], rho = c->v[1];
    std::string name = "custom";
    if (*mat) {
      const auto m = tw::find_material(c->text);
      if (!m)
        throw mc::UsageError("--material: unknown material '" + c->text +
                             "' (cast-iron, stainless-steel, aluminum, carbon-fiber)");
      e = m->young_Pa;
      rho = m->density_kg_m3;
      name = m->name;
    } else if (!*young) {
      throw mc::UsageError("beam: give --material NAME or --young PA --density KG_M3");
    }
    const double f = tw::beam_natural_frequency(e, rho, c->v[2], c->v[3]);
    mc::cli::emit(c->common, {{"first_mode_Hz", f}},
                  fmt::format("{} (E = {:.3g} Pa, rho = {:.4g} kg/m^3): first mode (eq. 3.2) {:.1f} Hz", name,
                              e, rho, f));
  });
}

void add_options(CLI::App& group) {
  auto c = std::make_shared<Calc>();
  auto* cmd =
      group.add_subcommand("options", "Evaluation of the actuator options against Table 4.3 (Table 4.7)");
  mc::cli::add_output_options(*cmd, c->common);
  cmd->callback([c] {
    const tw::TweezersSpecs specs;
    const auto rows = tw::evaluate_actuator_options(specs);
    nlohmann::json j{{"max_voltage_V", specs.max_voltage_V}, {"min_force_N", specs.min_force_N()}};
    std::string human =
        fmt::format("specifications (Table 4.3): supply <= {:.0f} V, force >= {:.2f} N (eq. 4.1)\n",
                    specs.max_voltage_V, specs.min_force_N());
    for (const auto& r : rows) {
      j["options"].push_back(tw::to_json(r));
      human += fmt::format("{:<36} supply {:>6.1f} V {}  force {:>8} {}  {:<7} difficulty {:<4} {}\n", r.name,
                           r.supply_voltage_V, r.meets_supply ? "ok " : "NO ",
                           r.force_N ? fmt::format("{:.2f} N", *r.force_N) : std::string("reported"),
                           r.meets_force ? "ok " : "NO ", r.active ? "active" : "passive", r.difficulty,
                           r.selected ? "<- selected" : "");
    }
    mc::cli::emit(c->common, j, human);
  });
}

void add_design(CLI::App& group) {
  group.require_subcommand(1);
  add_ballscrew(group);
  add_actuator(group);
  add_transmission(group);
  add_stiffness_force(group);
  add_amplifier(group);
  add_piezo_brake(group);
  add_beam(group);
  add_options(group);
}

const bool kRegistered = mc::cli::register_group(
    {"design", "TéléTweez design calculators (ch. 4, app. A, B, eq. 3.2)", 60, &add_design});

}  // namespace
}  // namespace design_commands
