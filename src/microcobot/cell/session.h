#pragma once
/// @file
/// A session of the platform: a scenario run from its configuration to its verdict, with
/// the recording and the session report (`microcobot run`).
///
/// Scenarios:
///  - "pick-place" (default): the scripted watchmaker of PickPlaceOperator picks a 300 um
///    part, transports it 2 mm at 100 um/s and places it on the target;
///  - "stale-master": the same, with the haptic master's readings frozen for
///    `stale_for_s` from `stale_at_s` during the transport (a stalled bus): the watchdog must
///    hold the slave and zero the force, and the operator finishes once readings resume.

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "microcobot/cell/pick_place_operator.h"
#include "microcobot/platform/platform.h"
#include "microcobot/report/report.h"

namespace mc::cell {

struct SessionParams {
  std::string scenario = "pick-place";
  /// Stop the session after this long (simulated time). Bounds: kMinDuration_s (a report
  /// needs samples to plot) to kMaxDuration_s (the recording's memory: ~0.3 MB per second).
  double max_duration_s = 120.0;
  static constexpr double kMinDuration_s = 0.01;
  static constexpr double kMaxDuration_s = 3600.0;
  double placement_tolerance_m = 5e-6;
  double stale_at_s = 12.0;  ///< stale-master: when the haptic readings freeze ...
  double stale_for_s = 0.5;  ///< ... and for how long
  PickPlaceOperatorParams operator_params;
  void validate() const;
};

/// Names of the scenarios, for --help and errors.
std::vector<std::string> scenario_names();

struct SessionResult {
  bool success = false;
  std::string verdict;  ///< one line: why it succeeded or failed
  double placement_error_m = 0.0;
  /// Operator-to-slave tracking error while engaged (Platform::tracking_error()).
  double tracking_error_rms_m = 0.0, tracking_error_max_m = 0.0;
  double duration_s = 0.0;  ///< simulated time
  std::uint64_t ticks = 0;
  std::uint64_t overruns = 0;
  double tick_mean_us = 0.0, tick_p99_us = 0.0, tick_max_us = 0.0;
  double wall_s = 0.0;  ///< wall-clock time of the run
  int clutches = 0;
  bool faulted = false;
  bool crashed = false;
  bool interrupted = false;  ///< stopped early on request (a signal); the verdict says so
  std::size_t telemetry_dropped = 0;
  std::vector<std::pair<std::string, double>> phases;  ///< phase name and start time [s]
  nlohmann::json to_json() const;
};

/// What a live recording says happened besides its telemetry, read from its /events and
/// /platform/status channels (live/recording_files.h): who drove, e-stops, refusals, errors.
struct RecordingStory {
  std::string version;             ///< the program that recorded it ("" when the recording does not say)
  std::string scene;               ///< the scene's kind
  bool console_control = false;    ///< a console client held control
  double console_control_s = 0.0;  ///< when it first took it (loop time)
  bool demo = false;               ///< the scripted demo operator drove
  std::vector<std::string> demo_phases;  ///< the demo's phases, in order
  int estops = 0, refusals = 0, errors = 0;
  struct Event {
    double t_s;
    int level;  ///< 0 info, 1 warning, 2 error
    std::string text;
  };
  std::vector<Event> events;  ///< the notable ones, in order
};

/// The figures of a recording (operator and haptic master, slave stage and microworld, gripper
/// and TéléTweez, loop timing), shared by the session report and the live recordings' reports.
/// `hand` is the first section's text: who moved the hand (the scripted operator, the console).
void add_recording_figures(report::Report& rep, const Recorder& rec, const std::string& hand);
/// The report of a live recording (`serve`, read back with read_telemetry_mcap): what happened
/// (from `story`), its span and the figures. Throws InvalidInput for an empty recording.
report::Report recording_report(const Recorder& rec, const std::string& name,
                                const RecordingStory& story = {});

class Session {
 public:
  /// Builds the platform (validates everything first).
  Session(const platform::PlatformConfig& config, const SessionParams& params);
  /// Runs the scenario to its end; `progress(t_s)` is called about once per simulated second.
  /// When `stop()` returns true (checked as often) the session ends early, interrupted.
  SessionResult run(const std::function<void(double)>& progress = {}, const std::function<bool()>& stop = {});
  /// The session report: trajectories, forces, gripper, loop timing, phases.
  report::Report report(const SessionResult& result) const;
  /// Writes recording.csv, recording.mcap (the same samples as JSON messages on
  /// /platform/telemetry, telemetry_json.h) and the report (index.html + figure CSVs) into `dir`. An
  /// interrupted session's recording starts with the comment line "# interrupted at ...".
  void write(const std::filesystem::path& dir, const SessionResult& result) const;

  platform::Platform& platform() { return *platform_; }
  const PickPlaceOperator& op() const { return *operator_; }

 private:
  SessionParams params_;
  std::unique_ptr<platform::Platform> platform_;
  std::unique_ptr<PickPlaceOperator> operator_;
};

}  // namespace mc::cell
