#pragma once
/// @file
/// Step 3 of the identification (thesis §2.5.2.3, Fig. 2.13, §2.6): the break-away strain z_ba of
/// each sawtooth run, and the surface z_ba(amplitude, frequency, direction) as the model's
/// BreakawayTable.
///
/// For each run, the measured mean slider velocity (position averaged over the first and the last
/// full period, after one settling period) is matched by the simulated one: with all other
/// parameters fixed (PE, asperities, PI, z_ba/|z_ss| = 0.667 of Table 2.8), |v(z_ba)| falls to zero
/// as z_ba grows to the PE stroke (no more slip). A coarse scan in log z_ba finds the decreasing
/// branch bracketing the target (the largest z_ba with |v| >= |v_meas|), then a monotone bracketed
/// search (Illinois regula falsi in log z_ba) solves |v(z_ba)| = |v_meas|.
/// Runs are independent: they are spread over threads, one ActuatorModel shared read-only and one
/// ActuatorState per simulation (one Params drives many States: docs/architecture.md).

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "microcobot/stickslip/actuator.h"
#include "microcobot/stickslip/breakaway_table.h"
#include "microcobot/stickslip/ident_record.h"

namespace mc::stickslip {

/// One measured sawtooth run.
struct SawtoothRun {
  std::string name;
  double amplitude_V = 0.0;
  double frequency_Hz = 0.0;
  Direction direction = Direction::kForward;
  MeasuredRecord rec;
};

struct BreakawayOptions {
  int sim_periods = 4;       ///< simulated periods after the settling period (velocity window)
  double min_sim_s = 0.004;  ///< simulate at least this long (more periods at high frequency)
  int scan_points = 10;      ///< coarse log-spaced scan of z_ba
  int max_iterations = 30;   ///< bracketed search
  double rel_tol = 2e-3;     ///< on z_ba
  /// A run "never steps" when its net motion per period is below this fraction of the PE's static
  /// stroke g H(A) (or below 1 nm): it is reported and skipped.
  double no_step_fraction = 0.01;
  unsigned threads = 0;  ///< 0: std::thread::hardware_concurrency()
};

/// The fit of one run.
struct RunFit {
  std::string name;
  double amplitude_V = 0.0, frequency_Hz = 0.0;
  Direction direction = Direction::kForward;
  double v_measured_m_s = 0.0;
  double v_simulated_m_s = 0.0;
  double z_ba_m = 0.0;
  int simulations = 0;
  bool ok = false;
  std::string skipped;  ///< why the run was skipped (empty when ok)
};

struct BreakawayResult {
  std::vector<RunFit> runs;
  BreakawayTable table;
  /// Table cells without a fitted run: between fitted cells of their frequency, interpolated
  /// linearly along amplitude (`filled`); beyond them (below the stepping threshold), or in a
  /// column without any fitted run, extrapolated from the fitted cells (`extrapolated`).
  std::vector<std::string> filled, extrapolated;
  std::size_t skipped = 0;
};

/// Mean slider velocity of `model` driven by `wave` with the break-away strain forced to
/// `z_ba_m`: one settling period, then the position averaged over the first and the last of
/// `periods` full periods. One local ActuatorState; the step loop does not allocate.
/// Throws mc::ComputationFailed on divergence.
double simulated_mean_velocity(const ActuatorModel& model, const Waveform& wave, double z_ba_m, int periods);

/// Identifies z_ba for every run and builds the table on the runs' (amplitude x frequency) grid.
/// `progress(done, total)` is called after each run (from worker threads, serialised).
/// Throws mc::InvalidInput if `runs` is empty and mc::ComputationFailed if a direction has no
/// usable run at all.
BreakawayResult identify_breakaway(const std::vector<SawtoothRun>& runs, const ActuatorModel& model,
                                   const BreakawayOptions& options = {},
                                   const std::function<void(std::size_t, std::size_t)>& progress = {});

/// The file name of a run: "sawtooth_<amplitude>V_<frequency>Hz_<forward|backward>.csv".
std::string sawtooth_file_name(double amplitude_V, double frequency_Hz, Direction direction);
/// Parses such a name; false if it does not match.
bool parse_sawtooth_file_name(const std::string& name, double& amplitude_V, double& frequency_Hz,
                              Direction& direction);
/// Reads every sawtooth_*.csv of `dir` (sorted by name). Throws mc::InvalidInput if there is none
/// or a file is malformed.
std::vector<SawtoothRun> read_sawtooth_runs(const std::filesystem::path& dir);

}  // namespace mc::stickslip
