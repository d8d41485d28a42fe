// `microcobot teleop delay-sweep`: the coupling system over a delayed, lossy link pushed into a
// stiff contact, unprotected, with time-domain passivity control or model-mediated
// (teleop/delayed_teleoperation.h, docs/concepts/teleoperation.md "Passivity under delay" and "Settling under
// long delay"). `teleop delay-validate`: the tuning and validation sets of delay cases
// (studies/delay_case_sets.h).

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/report/report.h"
#include "microcobot/studies/delay_case_sets.h"
#include "microcobot/teleop/delayed_teleoperation.h"

namespace teleop_commands {
namespace {

using mc::cli::CommonOptions;

/// The coupling's settings every teleop command takes.
struct CouplingOptions {
  mc::teleop::DelayedTeleopParams params;
  std::string mmt_passivity = "on";
  /// Applies what add() parsed into `params`; throws InvalidParams naming a bad value.
  const mc::teleop::DelayedTeleopParams& resolve() {
    mc::require(mmt_passivity == "on" || mmt_passivity == "off", "--mmt-passivity",
                "must be on or off, got '" + mmt_passivity + "'");
    params.mmt.passivity = mmt_passivity == "on";
    params.validate();
    return params;
  }
  void add(CLI::App& cmd) {
    cmd.add_option("--mmt-passivity", mmt_passivity,
                   "mmt: the model port's passivity controller, on or off (observe only) (default on)");
    cmd.add_option("--duration", params.duration_s, "Simulated time per case [s] (default 6)");
    cmd.add_option("--master-damping", params.master_damping_N_s_m,
                   "A passive damper on the handle [N s/m], any scheme (default 0)");
    cmd.add_option("--mmt-tau", params.mmt.time_constant_s,
                   "mmt: the master model's lag towards each estimate [s] (default 0.005)");
    cmd.add_option(
        "--mmt-prior-margin", params.mmt.prior_margin_m,
        "mmt: the prior wall is placed this much nearer than the geometry says [m] (default 1.5e-3)");
    cmd.add_option("--mmt-forgetting", params.mmt.estimator.forgetting,
                   "mmt: the slave estimator's forgetting factor per sample (default 0.999)");
    cmd.add_option(
        "--mmt-min-spread", params.mmt.estimator.min_spread_m,
        "mmt: spread (std) of the slave's positions before the stiffness is re-fitted [m] (default 2e-5)");
  }
};

struct SweepOptions {
  CommonOptions common;
  CouplingOptions coupling;
  std::vector<double> delays_s = {0.0, 0.01, 0.02, 0.05, 0.1, 0.2};
  std::vector<double> losses = {0.0, 0.2};
  std::vector<std::string> schemes = {"none", "tdpa", "mmt"};
  double jitter_fraction = 0.1;  ///< each way's jitter, as a fraction of its delay
  double wall_prior_error_m = 0.0;
  std::uint64_t seed = 1;
};

/// JSON number or null (nlohmann would print inf as null anyway; say so explicitly).
nlohmann::json finite_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json to_json(const mc::teleop::DelayCaseResult& r) {
  return {{"delay_s", r.c.delay_s},
          {"jitter_s", r.c.jitter_s},
          {"loss", r.c.loss},
          {"scheme", to_string(r.c.scheme)},
          {"passivity", r.passivity},
          {"stable", r.stable},
          {"settled", r.settled},
          {"settling_time_s", finite_or_null(r.settling_time_s)},
          {"steady_contact_force_N", r.steady_contact_force_N},
          {"contact_force_mean_N", finite_or_null(r.contact_force_mean_N)},
          {"contact_force_max_error", finite_or_null(r.contact_force_max_error)},
          {"min_observed_energy_J", r.min_observed_energy_J},
          {"max_handle_excursion_m", finite_or_null(r.max_handle_excursion_m)},
          {"rms_tracking_error_m", r.rms_tracking_error_m},
          {"max_handle_force_N", r.max_handle_force_N},
          {"max_contact_force_N", r.max_contact_force_N},
          {"dissipated_J", r.dissipated_J},
          {"final_model_wall_m", r.c.scheme == mc::teleop::Scheme::kMmt ? nlohmann::json(r.final_model_wall_m)
                                                                        : nlohmann::json(nullptr)},
          {"final_model_stiffness_N_m", r.c.scheme == mc::teleop::Scheme::kMmt
                                            ? nlohmann::json(r.final_model_stiffness_N_m)
                                            : nlohmann::json(nullptr)}};
}

std::string fmt_or(double v, double scale, const char* never) {
  return std::isfinite(v) ? fmt::format("{:.3f}", scale * v) : std::string(never);
}

std::vector<mc::teleop::Scheme> parse_schemes(const std::vector<std::string>& names) {
  std::vector<mc::teleop::Scheme> out;
  for (const auto& n : names) out.push_back(mc::teleop::scheme_from_string(n));
  mc::require(!out.empty(), "--schemes", "needs at least one of none, tdpa, mmt");
  return out;
}

void run_sweep(SweepOptions& o) {
  for (double d : o.delays_s) mc::require_in_range(d, 0.0, 2.0, "--delays");
  for (double l : o.losses) mc::require(l >= 0.0 && l < 1.0, "--losses", "must be within [0, 1)", l);
  mc::require_in_range(o.jitter_fraction, 0.0, 1.0, "--jitter");
  mc::require_in_range(o.wall_prior_error_m, -0.01, 0.01, "--wall-prior-error");
  const std::vector<mc::teleop::Scheme> schemes = parse_schemes(o.schemes);
  const mc::teleop::DelayedTeleopParams& p = o.coupling.resolve();
  nlohmann::json cases = nlohmann::json::array();
  double unstable_delay = -1.0;
  nlohmann::json all_settled = nlohmann::json::object();
  for (mc::teleop::Scheme s : schemes) all_settled[to_string(s)] = true;
  // For the report: the first unstable unprotected case and its protected twins.
  std::vector<mc::teleop::DelayCaseResult> shown;
  double shown_delay = -1.0;
  const std::size_t total = o.delays_s.size() * o.losses.size() * schemes.size();
  std::size_t done = 0;
  for (double loss : o.losses) {
    for (double delay : o.delays_s) {
      for (mc::teleop::Scheme scheme : schemes) {
        const mc::teleop::DelayCase c{
            delay, o.jitter_fraction * 0.5 * delay, loss, scheme, o.seed, o.wall_prior_error_m};
        auto r = mc::teleop::run_delay_case(p, c, /*keep_series=*/true);
        if (scheme == mc::teleop::Scheme::kNone && !r.stable && loss == 0.0 &&
            (unstable_delay < 0 || delay < unstable_delay))
          unstable_delay = delay;
        if (!r.settled) all_settled[to_string(scheme)] = false;
        cases.push_back(to_json(r));
        // The report shows the longest delay without loss, every scheme.
        if (loss == 0.0 && delay >= shown_delay) {
          if (delay > shown_delay) shown.clear();
          shown_delay = delay;
          shown.push_back(std::move(r));
        }
        mc::cli::progress("delay sweep", ++done, total);
      }
    }
  }
  nlohmann::json j{
      {"cases", cases},
      {"steady_contact_force_N", p.steady_contact_force_N()},
      {"all_settled", all_settled},
      {"unstable_delay_s", unstable_delay < 0 ? nlohmann::json(nullptr) : nlohmann::json(unstable_delay)}};
  std::string human = fmt::format(
      "steady contact force {:.3f} N; settled: handle p-p < {:g} mm and force within {:g} % over the last "
      "second\n"
      "round trip  loss  scheme  stable  settled  settling [s]  min PO [J]   handle p-p [mm]  force err "
      "[%]\n",
      p.steady_contact_force_N(), 1e3 * p.stable_excursion_m, 1e2 * p.settled_force_tolerance);
  for (const auto& c : cases) {
    auto num = [&](const char* key) {
      return c[key].is_null() ? std::numeric_limits<double>::infinity() : c[key].get<double>();
    };
    human += fmt::format(
        "{:8.0f} ms  {:3.0f} %  {:6}  {:6}  {:7}  {:>12}  {:10.3g}  {:>15}  {:>13}\n",
        1e3 * c["delay_s"].get<double>(), 1e2 * c["loss"].get<double>(), c["scheme"].get<std::string>(),
        c["stable"].get<bool>() ? "yes" : "NO", c["settled"].get<bool>() ? "yes" : "NO",
        fmt_or(num("settling_time_s"), 1.0, "never"), c["min_observed_energy_J"].get<double>(),
        fmt_or(num("max_handle_excursion_m"), 1e3, "diverged"),
        fmt_or(num("contact_force_max_error"), 1e2, "diverged"));
  }
  const bool lossless_unprotected =
      std::find(o.losses.begin(), o.losses.end(), 0.0) != o.losses.end() &&
      std::find(schemes.begin(), schemes.end(), mc::teleop::Scheme::kNone) != schemes.end();
  // unstable_delay_s is about the unprotected loop without loss: said only when that was run.
  if (lossless_unprotected)
    human += unstable_delay < 0 ? "the unprotected loop stayed stable at every delay\n"
                                : fmt::format("the unprotected loop is unstable from {:g} ms round trip\n",
                                              1e3 * unstable_delay);
  if (o.common.out) {
    mc::report::Report rep("teleop delay-sweep: passivity and settling under delay");
    rep.section("Sweep",
                "A scripted operator pushes the slave 10 mm (hand travel) into a stiff wall over a link "
                "with the round-trip delay, jitter and loss of each case; unprotected (position forward, "
                "force back), with time-domain passivity control at both ports (tdpa), or model-mediated "
                "(mmt: the handle feels a local model of the wall that the slave estimates).");
    std::vector<mc::report::Series> pp;
    for (mc::teleop::Scheme s : schemes) {
      std::vector<double> d, x;
      for (const auto& c : cases) {
        if (c["loss"].get<double>() != 0.0 || c["scheme"] != to_string(s) ||
            c["max_handle_excursion_m"].is_null())
          continue;
        d.push_back(c["delay_s"].get<double>());
        x.push_back(c["max_handle_excursion_m"].get<double>());
      }
      pp.push_back({to_string(s), d, x});
    }
    rep.add_figure({"Handle motion in the contact",
                    "Peak-to-peak of the handle over the last second (no loss).",
                    {"Round-trip delay", "s"},
                    {"Handle peak-to-peak", "m"},
                    pp});
    for (const auto& r : shown) {
      const std::string name = fmt::format("{:g} ms, {}", 1e3 * r.c.delay_s, to_string(r.c.scheme));
      rep.add_figure({"Handle and slave, " + name,
                      "",
                      {"Time", "s"},
                      {"Position", "m"},
                      {{"handle", r.t_s, r.handle_m}, {"slave", r.t_s, r.slave_m}}});
      rep.add_figure({"Forces, " + name,
                      "The force on the handle and the contact force at the slave.",
                      {"Time", "s"},
                      {"Force", "N"},
                      {{"handle", r.t_s, r.handle_force_N}, {"contact", r.t_s, r.contact_force_N}}});
      rep.add_figure({"Observed energy, " + name,
                      "tdpa, none: PO_m and PO_s; mmt: the model port's PO (master). Negative means energy "
                      "was generated.",
                      {"Time", "s"},
                      {"Energy", "J"},
                      {{"PO master", r.t_s, r.po_master_J}, {"PO slave", r.t_s, r.po_slave_J}}});
    }
    mc::cli::write_report_if_requested(o.common, rep);
  }
  mc::cli::emit(o.common, j, human);
}

struct ValidateOptions {
  CommonOptions common;
  CouplingOptions coupling;
  std::string set = "validation";
  int cases = 40;
  std::uint64_t seed = 20261125;
  std::string scheme = "mmt";
};

void run_validate(ValidateOptions& o) {
  mc::require(o.set == "tuning" || o.set == "validation", "--set",
              "must be tuning or validation, got '" + o.set + "'");
  mc::require(o.cases >= 1 && o.cases <= 1000, "--cases", "must be within [1, 1000]", o.cases);
  const mc::teleop::Scheme scheme = mc::teleop::scheme_from_string(o.scheme);
  o.coupling.resolve();
  const auto set =
      o.set == "tuning" ? mc::studies::tuning_set() : mc::studies::validation_set(o.cases, o.seed);
  const mc::studies::SetSummary s = mc::studies::run_case_set(o.coupling.params, set, scheme);
  nlohmann::json rows = nlohmann::json::array();
  std::string human =
      "round trip  jitter  loss  wall [N/m]    n  geometry err [mm]  noise [mN]  settled  settling [s]  "
      "handle "
      "p-p [mm]  "
      "force err [%]  min PO [J]\n";
  for (std::size_t i = 0; i < s.results.size(); ++i) {
    const auto& r = s.results[i];
    const auto& sc = s.set[i];
    nlohmann::json row = to_json(r);
    row["wall_stiffness_N_m"] = sc.wall_stiffness_N_m;
    row["wall_exponent"] = sc.wall_exponent;
    row["wall_prior_error_m"] = sc.c.wall_prior_error_m;
    row["force_noise_N"] = sc.force_noise_N;
    row["seed"] = sc.c.seed;
    rows.push_back(row);
    human += fmt::format(
        "{:8.1f} ms  {:4.1f} ms  {:3.0f} %  {:10.0f}  {:3.1f}  {:17.2f}  {:10.2f}  {:7}  {:>12}  {:>15}  "
        "{:>13}  "
        "{:10.3g}\n",
        1e3 * sc.c.delay_s, 1e3 * sc.c.jitter_s, 1e2 * sc.c.loss, sc.wall_stiffness_N_m, sc.wall_exponent,
        1e3 * sc.c.wall_prior_error_m, 1e3 * sc.force_noise_N, r.settled ? "yes" : "NO",
        fmt_or(r.settling_time_s, 1.0, "never"), fmt_or(r.max_handle_excursion_m, 1e3, "diverged"),
        fmt_or(r.contact_force_max_error, 1e2, "diverged"), r.min_observed_energy_J);
  }
  human += fmt::format(
      "{} set, {}: {}/{} settled; worst handle p-p {} mm, worst force error {} %, worst settling time {}, "
      "min PO {:.3g} J\n",
      o.set, o.scheme, s.settled, s.cases, fmt_or(s.worst_handle_excursion_m, 1e3, "diverged"),
      fmt_or(s.worst_force_error, 1e2, "diverged"),
      std::isfinite(s.worst_settling_time_s) ? fmt::format("{:.3f} s", s.worst_settling_time_s) : "never",
      s.min_observed_energy_J);
  // --out: one row per case (a diverged case's figures as inf would not be numbers: -1).
  mc::CsvTable table({"delay_s", "jitter_s", "loss", "wall_stiffness_N_m", "wall_exponent",
                      "wall_prior_error_m", "force_noise_N", "settled", "settling_time_s",
                      "max_handle_excursion_m", "contact_force_max_error", "min_observed_energy_J"});
  for (std::size_t i = 0; i < s.results.size(); ++i) {
    const auto& r = s.results[i];
    const auto& sc = s.set[i];
    auto or_minus_one = [](double v) { return std::isfinite(v) ? v : -1.0; };
    const double row[] = {sc.c.delay_s,
                          sc.c.jitter_s,
                          sc.c.loss,
                          sc.wall_stiffness_N_m,
                          sc.wall_exponent,
                          sc.c.wall_prior_error_m,
                          sc.force_noise_N,
                          r.settled ? 1.0 : 0.0,
                          or_minus_one(r.settling_time_s),
                          or_minus_one(r.max_handle_excursion_m),
                          or_minus_one(r.contact_force_max_error),
                          r.min_observed_energy_J};
    table.add_row(row);
  }
  nlohmann::json j{{"set", o.set},
                   {"scheme", o.scheme},
                   {"seed", o.set == "validation" ? nlohmann::json(o.seed) : nlohmann::json(nullptr)},
                   {"mmt_time_constant_s", o.coupling.params.mmt.time_constant_s},
                   {"cases", s.cases},
                   {"settled", s.settled},
                   {"worst_handle_excursion_m", finite_or_null(s.worst_handle_excursion_m)},
                   {"worst_force_error", finite_or_null(s.worst_force_error)},
                   {"worst_settling_time_s", finite_or_null(s.worst_settling_time_s)},
                   {"min_observed_energy_J", s.min_observed_energy_J},
                   {"results", rows}};
  mc::cli::write_result_table(o.common, "cases.csv", table, {{"set", o.set}, {"settled", s.settled}});
  mc::cli::emit(o.common, j, human);
}

void add_teleop(CLI::App& group) {
  auto o = std::make_shared<SweepOptions>();
  auto* cmd =
      group.add_subcommand("delay-sweep",
                           "The coupling over a delayed, lossy link into a stiff contact: unprotected, "
                           "TDPA and model-mediated");
  cmd->add_option("--delays", o->delays_s, "Round-trip delays [s] (default 0 0.01 0.02 0.05 0.1 0.2)");
  cmd->add_option("--losses", o->losses, "Loss probabilities each way (default 0 0.2)");
  cmd->add_option("--jitter", o->jitter_fraction, "Jitter each way as a fraction of its delay (default 0.1)");
  cmd->add_option("--schemes", o->schemes, "Schemes to run: none, tdpa, mmt (default all three)");
  cmd->add_option("--seed", o->seed, "The links' random seed (default 1)");
  cmd->add_option("--wall-prior-error", o->wall_prior_error_m,
                  "mmt: the geometry's error on the wall's position [m] (default 0)");
  cmd->add_option("--wall-stiffness", o->coupling.params.wall_stiffness_N_m,
                  "The contact's stiffness as the handle feels it, at 1 mm deep [N/m] (default 1000)");
  cmd->add_option("--wall-exponent", o->coupling.params.wall_exponent,
                  "The wall's force law f = k d (d / 1 mm)^(n-1): 1 a spring, 1.5 Hertz (default 1)");
  o->coupling.add(*cmd);
  mc::cli::add_output_options(*cmd, o->common);
  cmd->callback([o] { run_sweep(*o); });

  auto v = std::make_shared<ValidateOptions>();
  auto* val = group.add_subcommand("delay-validate",
                                   "The tuning set or a seeded random validation set of delay, jitter, loss, "
                                   "wall stiffness, geometry error and sensor noise cases");
  val->add_option("--set", v->set, "tuning or validation (default validation)");
  val->add_option("--cases", v->cases, "Validation cases (default 40)");
  val->add_option("--seed", v->seed, "Validation set's seed (default 20261125)");
  val->add_option("--scheme", v->scheme, "none, tdpa or mmt (default mmt)");
  v->coupling.add(*val);
  mc::cli::add_output_options(*val, v->common);
  val->callback([v] { run_validate(*v); });
}

const bool kRegistered = mc::cli::register_group(
    {"teleop", "The coupling system over a network link: delay, jitter, loss, passivity", 7, &add_teleop});

}  // namespace
}  // namespace teleop_commands
