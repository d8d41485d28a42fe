// `microcobot teleop delay-sweep`: the coupling system over a delayed, lossy link pushed into a
// stiff contact, with and without time-domain passivity control (issue #17;
// control/delayed_teleoperation.h, docs/model.md "Passivity under delay").

#include <memory>
#include <vector>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/control/delayed_teleoperation.h"
#include "microcobot/core/error.h"
#include "microcobot/report/report.h"

namespace {

namespace ctl = mc::control;
using mc::cli::CommonOptions;

struct SweepOptions {
  CommonOptions common;
  std::vector<double> delays_s = {0.0, 0.01, 0.02, 0.05, 0.1, 0.2};
  std::vector<double> losses = {0.0, 0.2};
  double jitter_fraction = 0.1;  ///< each way's jitter, as a fraction of its delay
  ctl::DelayedTeleopParams params;
};

nlohmann::json to_json(const ctl::DelayCaseResult& r) {
  return {{"delay_s", r.c.delay_s},
          {"jitter_s", r.c.jitter_s},
          {"loss", r.c.loss},
          {"passivity", r.c.passivity},
          {"stable", r.stable},
          {"min_observed_energy_J", r.min_observed_energy_J},
          {"max_handle_excursion_m", r.max_handle_excursion_m},
          {"rms_tracking_error_m", r.rms_tracking_error_m},
          {"max_handle_force_N", r.max_handle_force_N},
          {"max_contact_force_N", r.max_contact_force_N},
          {"dissipated_J", r.dissipated_J}};
}

void run_sweep(const SweepOptions& o) {
  for (double d : o.delays_s) mc::require_in_range(d, 0.0, 2.0, "--delays");
  for (double l : o.losses) mc::require(l >= 0.0 && l < 1.0, "--losses", "must be within [0, 1)", l);
  mc::require_in_range(o.jitter_fraction, 0.0, 1.0, "--jitter");
  const ctl::DelayedTeleopParams& p = o.params;
  nlohmann::json cases = nlohmann::json::array();
  double unstable_delay = -1.0;
  std::vector<ctl::DelayCaseResult> shown;  // the first unstable unprotected case and its protected twin
  const std::size_t total = o.delays_s.size() * o.losses.size() * 2;
  std::size_t done = 0;
  for (double loss : o.losses) {
    for (double delay : o.delays_s) {
      for (bool passivity : {false, true}) {
        const ctl::DelayCase c{delay, o.jitter_fraction * 0.5 * delay, loss, passivity, 1};
        const bool show = shown.size() < 2 && loss == 0.0 && (shown.size() == 1 ? passivity : !passivity);
        auto r = ctl::run_delay_case(p, c, /*keep_series=*/true);
        if (!passivity && !r.stable && loss == 0.0 && (unstable_delay < 0 || delay < unstable_delay))
          unstable_delay = delay;
        cases.push_back(to_json(r));
        if (show && (!r.stable || shown.size() == 1)) shown.push_back(std::move(r));
        mc::cli::progress("delay sweep", ++done, total);
      }
    }
  }
  nlohmann::json j{
      {"cases", cases},
      {"unstable_delay_s", unstable_delay < 0 ? nlohmann::json(nullptr) : nlohmann::json(unstable_delay)}};
  std::string human = "round trip  loss  passivity  stable  min PO [J]   handle p-p [mm]\n";
  for (const auto& c : cases)
    human += fmt::format("{:8.0f} ms  {:4.0f} %  {:9}  {:6}  {:10.3g}  {:8.3f}\n",
                         1e3 * c["delay_s"].get<double>(), 1e2 * c["loss"].get<double>(),
                         c["passivity"].get<bool>() ? "on" : "off", c["stable"].get<bool>() ? "yes" : "NO",
                         c["min_observed_energy_J"].get<double>(),
                         1e3 * c["max_handle_excursion_m"].get<double>());
  human += unstable_delay < 0 ? "the unprotected loop stayed stable at every delay\n"
                              : fmt::format("the unprotected loop is unstable from {:g} ms round trip\n",
                                            1e3 * unstable_delay);
  if (o.common.out) {
    mc::report::Report rep("teleop delay-sweep: passivity under delay");
    rep.section("Sweep",
                "A scripted operator pushes the slave 10 mm (hand travel) into a stiff wall over a link "
                "with the round-trip delay, jitter and loss of each case; position forward, force back, "
                "with and without time-domain passivity control at both ports.");
    std::vector<double> d_off, x_off, d_on, x_on;
    for (const auto& c : cases) {
      if (c["loss"].get<double>() != 0.0) continue;
      (c["passivity"].get<bool>() ? d_on : d_off).push_back(c["delay_s"].get<double>());
      (c["passivity"].get<bool>() ? x_on : x_off).push_back(c["max_handle_excursion_m"].get<double>());
    }
    rep.add_figure({"Handle motion in the contact",
                    "Peak-to-peak of the handle over the last second (no loss).",
                    {"Round-trip delay", "s"},
                    {"Handle peak-to-peak", "m"},
                    {{"unprotected", d_off, x_off}, {"passivity control", d_on, x_on}}});
    for (const auto& r : shown) {
      const std::string name =
          fmt::format("{:g} ms, passivity {}", 1e3 * r.c.delay_s, r.c.passivity ? "on" : "off");
      rep.add_figure({"Handle and slave, " + name,
                      "",
                      {"Time", "s"},
                      {"Position", "m"},
                      {{"handle", r.t_s, r.handle_m}, {"slave", r.t_s, r.slave_m}}});
      rep.add_figure({"Observed energy, " + name,
                      "PO_m and PO_s: negative means the channel generated energy.",
                      {"Time", "s"},
                      {"Energy", "J"},
                      {{"PO master", r.t_s, r.po_master_J}, {"PO slave", r.t_s, r.po_slave_J}}});
    }
    mc::cli::write_report_if_requested(o.common, rep);
  }
  mc::cli::emit(o.common, j, human);
}

void add_teleop(CLI::App& group) {
  auto o = std::make_shared<SweepOptions>();
  auto* cmd = group.add_subcommand("delay-sweep",
                                   "The coupling over a delayed, lossy link into a stiff contact, "
                                   "with and without passivity control");
  cmd->add_option("--delays", o->delays_s, "Round-trip delays [s] (default 0 0.01 0.02 0.05 0.1 0.2)");
  cmd->add_option("--losses", o->losses, "Loss probabilities each way (default 0 0.2)");
  cmd->add_option("--jitter", o->jitter_fraction, "Jitter each way as a fraction of its delay (default 0.1)");
  cmd->add_option("--duration", o->params.duration_s, "Simulated time per case [s] (default 6)");
  cmd->add_option("--wall-stiffness", o->params.wall_stiffness_N_m,
                  "The contact's stiffness as the handle feels it [N/m] (default 1000)");
  mc::cli::add_output_options(*cmd, o->common);
  cmd->callback([o] { run_sweep(*o); });
}

const bool kRegistered = mc::cli::register_group(
    {"teleop", "The coupling system over a network link: delay, jitter, loss, passivity", 7, &add_teleop});

}  // namespace
