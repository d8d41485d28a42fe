// `microcobot run`: the platform's main job. Builds the platform from its configuration, runs a
// scenario with the scripted operator, writes the session report and recording, and prints
// the verdict. Exit 4 when the scenario fails (the report is still written).

#include <cmath>
#include <memory>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/cell/session.h"
#include "microcobot/core/error.h"
#include "microcobot/core/params.h"
#include "signals.h"

namespace run_commands {
namespace {

namespace pf = mc::platform;

struct RunOptions {
  mc::cli::CommonOptions common;
  std::optional<std::filesystem::path> config;
  std::string scenario = "pick-place";
  double duration_s = 120.0;
  bool realtime = false;
  bool print_config = false;
};

pf::PlatformConfig load_config(const RunOptions& o) {
  if (o.config) return pf::load_platform_config(*o.config);
  pf::PlatformConfig c;
  c.validate();
  return c;
}

void run(const RunOptions& o) {
  auto config = load_config(o);
  if (o.print_config) {
    mc::cli::emit(o.common, mc::params_to_json(config), mc::params_to_yaml(config));
    return;
  }
  if (o.realtime) config.loop.realtime = true;
  mc::cell::SessionParams sp;
  sp.scenario = o.scenario;
  sp.max_duration_s = o.duration_s;
  sp.validate();
  // A signal from here on stops the run cleanly (one that came while the session was built
  // stops it at its start): the recording and report are written, marked as interrupted, and the
  // command exits 128 + signal.
  mc::cli::set_cooperative_interrupts(true);
  mc::cell::Session session(config, sp);
  const auto total = static_cast<std::size_t>(std::ceil(o.duration_s));
  const auto result = session.run(
      [&](double t) {
        mc::cli::progress("run " + o.scenario, static_cast<std::size_t>(std::lround(t)), total);
      },
      [] { return mc::cli::interrupt_signal() != 0; });
  const auto dir = o.common.out ? *o.common.out : mc::cli::stage_output("out/session");
  session.write(dir, result);
  mc::cli::set_cooperative_interrupts(false);
  if (result.interrupted) throw mc::cli::Interrupted(mc::cli::interrupt_signal());
  // A signal after the session ended, while its recording and report were written: they are
  // whole, so they are moved into place, and the command still exits 128 + signal (docs/cli.md).
  if (const int sig = mc::cli::interrupt_signal(); sig != 0) throw mc::cli::Interrupted(sig, true);
  auto summary = result.to_json();
  summary["scenario"] = o.scenario;
  summary["report"] = (dir / "index.html").string();
  summary["recording"] = (dir / "recording.csv").string();
  summary["recording_mcap"] = (dir / "recording.mcap").string();
  mc::cli::emit(o.common, summary,
                fmt::format("{}: {} (placement error {:.2f} um, {:.1f} s simulated in {:.1f} s, {} ticks, "
                            "tick mean {:.1f} us, p99 {:.1f} us, {} overruns)\nsession report: {}",
                            o.scenario, result.verdict, 1e6 * result.placement_error_m, result.duration_s,
                            result.wall_s, result.ticks, result.tick_mean_us, result.tick_p99_us,
                            result.overruns, (dir / "index.html").string()));
  if (!result.success) {
    // The report of a failed session is what tells why: it is kept (whole), and then exit 4.
    mc::cli::commit_outputs();
    throw mc::ComputationFailed("scenario " + o.scenario + " failed: " + result.verdict);
  }
}

void add_run(CLI::App& cmd) {
  auto o = std::make_shared<RunOptions>();
  // No CLI11 existence check: a missing file is invalid input (exit 3), as for --params.
  cmd.add_option("--config", o->config, "Platform configuration (YAML; keys as --print-config shows)");
  cmd.add_option("--scenario", o->scenario, "Scenario: pick-place (default) or stale-master")
      ->check(CLI::IsMember({"pick-place", "stale-master"}));
  cmd.add_option("--duration", o->duration_s, "Longest simulated time [s] (default 120)")
      ->check(
          mc::cli::Range(mc::cell::SessionParams::kMinDuration_s, mc::cell::SessionParams::kMaxDuration_s));
  cmd.add_flag("--realtime", o->realtime, "Pace the loop to the wall clock (SCHED_FIFO when permitted)");
  cmd.add_flag("--print-config", o->print_config, "Print the configuration (default or --config) and exit");
  cmd.add_flag("--json", o->common.json, "Print a machine-readable JSON summary on stdout");
  cmd.add_option("--out", o->common.out,
                 "Directory of the session report and recording (default out/session)");
  cmd.callback([o] { run(*o); });
}

const bool kRegistered = mc::cli::register_group(
    {"run", "Run the platform: a teleoperated pick-and-place scenario with its session report", 5, &add_run});

}  // namespace
}  // namespace run_commands
