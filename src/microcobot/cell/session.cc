#include "microcobot/cell/session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/platform/driver_registry.h"
#include "microcobot/platform/telemetry_json.h"

namespace mc::cell {
namespace {

std::vector<double> column(const Recorder& r, const std::string& name) { return r.channel(name); }

std::vector<double> scaled(std::vector<double> v, double k) {
  for (double& x : v) x *= k;
  return v;
}

const std::string kScriptedHand =
    "The scripted operator's hand and the handle of the dual-stage interface, relative to the "
    "Pantograph's workspace centre. The hand travels 100 times the slave's motion; the clutch "
    "brings it back across the workspace while the slave holds.";

// Plotted in the units a person reads at this scale (the figures' CSVs say which).
constexpr double kUm = 1e6, kUN = 1e6;

}  // namespace

std::vector<std::string> scenario_names() { return {"pick-place", "stale-master"}; }

void SessionParams::validate() const {
  const auto names = scenario_names();
  if (std::find(names.begin(), names.end(), scenario) == names.end()) {
    throw UsageError("unknown scenario '" + scenario + "' (expected pick-place or stale-master)");
  }
  require_in_range(max_duration_s, kMinDuration_s, kMaxDuration_s, "max_duration_s");
  require_positive(placement_tolerance_m, "placement_tolerance_m");
  require_non_negative(stale_at_s, "stale_at_s");
  require_positive(stale_for_s, "stale_for_s");
  operator_params.validate();
}

nlohmann::json SessionResult::to_json() const {
  nlohmann::json j;
  j["success"] = success;
  j["verdict"] = verdict;
  j["placement_error_m"] = placement_error_m;
  j["tracking_error_rms_m"] = tracking_error_rms_m;
  j["tracking_error_max_m"] = tracking_error_max_m;
  j["ticks"] = ticks;
  j["overruns"] = overruns;
  j["tick_mean_us"] = tick_mean_us;
  j["tick_p99_us"] = tick_p99_us;
  j["tick_max_us"] = tick_max_us;
  j["duration_s"] = duration_s;
  j["wall_s"] = wall_s;
  j["clutches"] = clutches;
  j["faulted"] = faulted;
  j["crashed"] = crashed;
  j["interrupted"] = interrupted;
  j["telemetry_dropped"] = telemetry_dropped;
  nlohmann::json ph = nlohmann::json::object();
  for (const auto& [name, t] : phases) ph[name] = t;
  j["phases_s"] = ph;
  return j;
}

Session::Session(const platform::PlatformConfig& config, const SessionParams& params) : params_(params) {
  params_.validate();
  require(!config.optical_trap_scene(), "microworld",
          "the scripted session is the pick-and-place: run it on the pick-place scene");
  require(config.devices.simulated() || config.devices.gripper == "simulated", "devices.gripper",
          "the scripted pick-and-place on a driver set needs `gripper: simulated` (a part to pick)");
  platform_ = platform::make_platform(config);  // the simulation, or a driver set under a simulated gripper
  operator_ = std::make_unique<PickPlaceOperator>(*platform_, params_.operator_params);
  const bool stale = params_.scenario == "stale-master";
  devices::SimulatedHapticMaster* haptic = platform_->simulation().haptic;
  platform_->set_operator([this, stale, haptic](const runtime::TickInfo& t) {
    if (stale) {
      haptic->freeze_readings(t.t_s >= params_.stale_at_s &&
                              t.t_s < params_.stale_at_s + params_.stale_for_s);
    }
    operator_->act(t);
  });
}

SessionResult Session::run(const std::function<void(double)>& progress, const std::function<bool()>& stop) {
  const auto start = std::chrono::steady_clock::now();
  platform::Platform& p = *platform_;
  bool interrupted = false;
  while (!operator_->done() && !operator_->gave_up() && !p.faulted() &&
         p.loop().time_s() < params_.max_duration_s - 1e-9) {
    p.run(std::min(1.0, params_.max_duration_s - p.loop().time_s()));
    if (progress) progress(p.loop().time_s());
    if (stop && stop()) {
      interrupted = true;
      break;
    }
  }
  SessionResult r;
  r.interrupted = interrupted;
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto& loop = p.loop();
  r.duration_s = loop.time_s();
  r.ticks = loop.ticks();
  r.overruns = loop.overruns();
  r.tick_mean_us = 1e6 * loop.tick_stats().mean_s();
  r.tick_p99_us = 1e6 * loop.tick_stats().quantile_s(0.99);
  r.tick_max_us = 1e6 * loop.tick_stats().max_s();
  r.clutches = operator_->clutches();
  r.faulted = p.faulted();
  const devices::SimulatedGripper& g = *p.simulation().gripper;
  const auto& w = g.world_state();
  r.crashed = w.crashed;
  r.placement_error_m = g.world().placement_error_m(w);
  r.telemetry_dropped = p.telemetry_dropped();
  r.tracking_error_rms_m = p.tracking_error().rms_m();
  r.tracking_error_max_m = p.tracking_error().max_m;
  using Phase = PickPlaceOperator::Phase;
  for (int i = 0; i <= static_cast<int>(Phase::kDone); ++i) {
    const double t = operator_->phase_start_s(static_cast<Phase>(i));
    if (std::isfinite(t))
      r.phases.emplace_back(std::string(PickPlaceOperator::name(static_cast<Phase>(i))), t);
  }

  const bool placed =
      w.phase == microworld::PartPhase::kOnSubstrate && r.placement_error_m <= params_.placement_tolerance_m;
  if (r.interrupted) {
    r.verdict =
        fmt::format("interrupted at t = {:g} s (simulated), before the operator finished", r.duration_s);
  } else if (r.faulted) {
    r.verdict = "a device faulted: every device went to its safe state";
  } else if (operator_->gave_up()) {
    r.verdict = "the operator gave up in phase '" +
                std::string(PickPlaceOperator::name(operator_->failed_phase())) + "' after " +
                std::to_string(params_.operator_params.phase_timeout_s) + " s";
  } else if (!operator_->done()) {
    r.verdict = "the session reached its maximum duration before the operator finished";
  } else if (r.crashed) {
    r.verdict = "a finger tip crashed into the substrate";
  } else if (!placed) {
    r.verdict = "the part is not on the substrate within the tolerance of the target";
  } else {
    r.verdict = "part placed and released";
  }
  r.success = !r.interrupted && operator_->done() && !r.faulted && !r.crashed && placed;

  if (params_.scenario == "stale-master" && r.success) {
    // While the readings were stale (after the watchdog's timeout) the slave must hold and the
    // haptic force be zero.
    const auto& rec = p.recording();
    const auto t = rec.channel("t_s"), stale = rec.channel("stale"), fx = rec.channel("haptic_force_x_N"),
               fy = rec.channel("haptic_force_y_N"), tx = rec.channel("target_x_m");
    double max_force = 0.0, target_motion = 0.0, held_s = 0.0,
           first = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (stale[i] < 0.5) continue;
      if (std::isnan(first)) first = tx[i];
      max_force = std::max({max_force, std::abs(fx[i]), std::abs(fy[i])});
      target_motion = std::max(target_motion, std::abs(tx[i] - first));
      held_s += 1.0 / (platform_->config().loop.base_rate_Hz / platform_->config().loop.telemetry_divisor);
    }
    if (held_s < 0.5 * params_.stale_for_s || max_force > 0.0 || target_motion > 0.0) {
      r.success = false;
      r.verdict = "the watchdog did not hold the slave with zero force while the master was stale";
    } else {
      r.verdict += "; the slave held with zero force for " + std::to_string(held_s) + " s of stale readings";
    }
  }
  return r;
}

report::Report Session::report(const SessionResult& r) const {
  const Recorder& rec = platform_->recording();
  report::Report rep("microcobot session: " + params_.scenario);
  std::string phases;
  for (const auto& [name, start] : r.phases)
    phases += name + " at " + std::to_string(start).substr(0, 6) + " s; ";
  rep.section("Outcome", r.verdict + ".\n\nPhases: " + phases);
  rep.add_text_result("success", r.success ? "yes" : "no");
  rep.add_result("placement error", r.placement_error_m, "m");
  rep.add_result("operator-to-slave tracking error (RMS, engaged)", r.tracking_error_rms_m, "m");
  rep.add_result("operator-to-slave tracking error (max, engaged)", r.tracking_error_max_m, "m");
  rep.add_result("simulated duration", r.duration_s, "s");
  rep.add_result("clutches (indexing)", r.clutches);
  rep.add_text_result("faulted", r.faulted ? "yes" : "no");

  add_recording_figures(rep, rec, kScriptedHand);
  rep.add_result("ticks", static_cast<double>(r.ticks));
  rep.add_result("overruns", static_cast<double>(r.overruns));
  rep.add_result("mean tick", r.tick_mean_us * 1e-6, "s");
  rep.add_result("p99 tick", r.tick_p99_us * 1e-6, "s");
  rep.add_result("max tick", r.tick_max_us * 1e-6, "s");
  rep.add_result("wall time", r.wall_s, "s");
  return rep;
}

void add_recording_figures(report::Report& rep, const Recorder& rec, const std::string& hand) {
  const auto t = column(rec, "t_s");
  auto series = [&](const std::string& name, const std::string& channel, double k = 1.0) {
    return report::Series{name, t, scaled(column(rec, channel), k)};
  };
  rep.section("Operator and haptic master", hand);
  rep.add_figure({"Hand and handle",
                  "x and y of the hand (set by the operator) and of the handle.",
                  {"Time", "s"},
                  {"Position", "mm"},
                  {series("hand x", "hand_x_m", 1e3), series("handle x", "handle_x_m", 1e3),
                   series("hand y", "hand_y_m", 1e3), series("handle y", "handle_y_m", 1e3)}});
  rep.add_figure({"Haptic force",
                  "Force commanded to the handle (the slave's contact force x 1e4, capped).",
                  {"Time", "s"},
                  {"Force", "N"},
                  {series("x", "haptic_force_x_N"), series("y", "haptic_force_y_N"),
                   series("Pantograph y (low band)", "pantograph_y_N")}});
  rep.add_figure({"Coupling state",
                  "Deadman held, clutch pressed, coupling engaged, masters stale (0/1).",
                  {"Time", "s"},
                  {"State", ""},
                  {series("deadman", "deadman"), series("clutch", "clutch"), series("engaged", "engaged"),
                   series("stale", "stale")}});

  rep.section("Slave stage and microworld",
              "The finger tips (the stage's true position plus the mount offset), the teleoperation target "
              "and the part, in the world frame.");
  rep.add_figure({"Slave x",
                  "",
                  {"Time", "s"},
                  {"Position", "um"},
                  {series("target x", "target_x_m", kUm), series("tips x", "slave_x_m", kUm),
                   series("part x", "part_x_m", kUm)}});
  rep.add_figure({"Slave z",
                  "",
                  {"Time", "s"},
                  {"Height", "um"},
                  {series("target z", "target_z_m", kUm), series("tips z", "slave_z_m", kUm),
                   series("part z", "part_z_m", kUm)}});
  rep.add_figure(
      {"Path in the x-z plane",
       "Where the tips and the part went (side view).",
       {"x", "um"},
       {"z", "um"},
       {report::Series{"tips", scaled(column(rec, "slave_x_m"), kUm), scaled(column(rec, "slave_z_m"), kUm)},
        report::Series{"part", scaled(column(rec, "part_x_m"), kUm), scaled(column(rec, "part_z_m"), kUm)}}});
  rep.add_figure(
      {"Contact force on the gripper",
       "",
       {"Time", "s"},
       {"Force", "uN"},
       {series("x", "contact_x_N", kUN), series("y", "contact_y_N", kUN), series("z", "contact_z_N", kUN)}});
  rep.add_figure({"Drive voltages (sampled at 1 kHz)",
                  "The axes' drive voltage at the telemetry instants.",
                  {"Time", "s"},
                  {"Voltage", "V"},
                  {series("x", "u_x_V"), series("y", "u_y_V"), series("z", "u_z_V")}});

  rep.section("Gripper and TéléTweez",
              "The TéléTweez tip opening drives the gripper opening (x 0.06); the grip "
              "force comes back to the operator's fingers (x 100).");
  rep.add_figure(
      {"Openings",
       "",
       {"Time", "s"},
       {"Opening", "um"},
       {series("TéléTweez x 0.06", "tweezers_opening_m", 0.06 * kUm),
        series("gripper command", "gripper_command_m", kUm), series("gripper", "gripper_opening_m", kUm)}});
  rep.add_figure({"Grip forces",
                  "",
                  {"Time", "s"},
                  {"Force", "uN"},
                  {series("slave grip", "grip_force_N", kUN),
                   series("finger force / 100", "finger_force_N", 0.01 * kUN)}});

  rep.section("Loop timing",
              "Compute time of the 10 kHz loop's ticks that run every task (slave control, telemetry: "
              "one in ten, the heaviest), on the wall clock and on the loop thread's CPU clock (a "
              "preemption by another thread counts on the wall clock only). An overrun is a tick longer "
              "than the period.");
  std::vector<report::Series> ticks = {series("tick (wall)", "tick_us")};
  if (rec.has_channel("tick_cpu_us")) ticks.push_back(series("tick (loop thread CPU)", "tick_cpu_us"));
  rep.add_figure({"Tick compute time", "", {"Time", "s"}, {"Tick", "us"}, std::move(ticks)});
}

namespace {

// Who moved the hand, and how the slave followed, as the recording's status and events tell it.
std::string live_hand_text(const RecordingStory& story) {
  std::string who;
  if (story.demo && story.console_control) {
    who = "Part of this session was driven from the console (a client took control at t = " +
          fmt::format("{:.1f}", story.console_control_s) +
          " s) and part by the scripted demo operator, whose hand moves the haptic master.";
  } else if (story.demo) {
    who = "The scripted demo operator drove this session: its hand moves the haptic master's handle.";
  } else if (story.console_control) {
    who = "This session was hand-operated from the browser console (a client took control at t = " +
          fmt::format("{:.1f}", story.console_control_s) +
          " s): the console's commands set the slave's target directly, so the hand and the handle "
          "below rest where the haptic master sits and its force stays zero.";
  } else {
    who = "Nobody drove in this session (no client took control, the demo did not run): the stage held.";
  }
  return who + " Hand and handle are relative to the Pantograph's workspace centre.";
}

std::string yes_no(bool b) { return b ? "yes" : "no"; }

}  // namespace

report::Report recording_report(const Recorder& rec, const std::string& name, const RecordingStory& story) {
  report::Report rep("microcobot recording: " + name);
  const auto t = column(rec, "t_s");
  if (t.empty()) throw InvalidInput(name, 0, "the recording holds no sample");
  const auto tick = column(rec, "tick_us");
  double tick_max = 0.0;
  for (double v : tick)
    if (std::isfinite(v)) tick_max = std::max(tick_max, v);
  std::string text = "The live session recorded by `microcobot serve`" +
                     (story.version.empty() ? std::string() : " (" + story.version + ")") + " in " + name +
                     (story.scene.empty() ? std::string() : ", scene " + story.scene) +
                     ", from t = " + fmt::format("{:.1f}", t.front()) + " s to " +
                     fmt::format("{:.1f}", t.back()) + " s of live time (" + std::to_string(rec.size()) +
                     " samples plotted).";
  if (story.demo && !story.demo_phases.empty()) {
    text += "\n\nThe demo went through: ";
    for (std::size_t i = 0; i < story.demo_phases.size(); ++i) text += (i ? ", " : "") + story.demo_phases[i];
    text += ".";
  }
  rep.section("Recording", text);
  rep.add_text_result("driven from the console", yes_no(story.console_control));
  rep.add_text_result("scripted demo", yes_no(story.demo));
  rep.add_result("e-stops", story.estops);
  rep.add_result("refused messages", story.refusals);
  rep.add_result("start (live time)", t.front(), "s");
  rep.add_result("duration", t.back() - t.front(), "s");
  rep.add_result("samples plotted", static_cast<double>(rec.size()));
  rep.add_result("max sampled tick", tick_max * 1e-6, "s");
  if (!story.events.empty()) {
    // One paragraph per event (the page splits paragraphs at blank lines); the first 40.
    std::string events;
    const std::size_t shown = std::min<std::size_t>(story.events.size(), 40);
    for (std::size_t i = 0; i < shown; ++i) {
      const auto& e = story.events[i];
      events += fmt::format("t = {:.1f} s: {}{}\n\n", e.t_s,
                            e.level >= 2   ? "error, "
                            : e.level == 1 ? "warning, "
                                           : "",
                            e.text);
    }
    if (shown < story.events.size()) events += fmt::format("... and {} more.", story.events.size() - shown);
    rep.section("What happened", events);
  }
  add_recording_figures(rep, rec, live_hand_text(story));
  return rep;
}

void Session::write(const std::filesystem::path& dir, const SessionResult& result) const {
  ensure_writable_dir(dir);
  std::vector<std::string> comment;
  if (result.interrupted) comment.push_back(result.verdict);
  write_csv(dir / "recording.csv", platform_->recording().to_table(), comment);
  platform::write_telemetry_mcap(platform_->recording(), platform_->telemetry_schema(),
                                 dir / "recording.mcap");
  report(result).write(dir);
}

}  // namespace mc::cell
