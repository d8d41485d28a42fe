#pragma once
/// @file
/// Named sets of delay cases for "tune on one set, judge on another": the tuning
/// set, a fixed grid on which the model-mediated scheme's lag was chosen, and the validation
/// set, cases drawn at random from a seed over the delays, jitters, losses, wall stiffnesses,
/// geometry errors and force-sensor noises the scheme must handle. docs/concepts/teleoperation.md names both.

#include <cstdint>
#include <vector>

#include "microcobot/teleop/delayed_teleoperation.h"

namespace mc::studies {

/// One case of a set: the link and the contact it meets.
struct SetCase {
  teleop::DelayCase c;
  double wall_stiffness_N_m = 1000.0;
  double wall_exponent = 1.0;  ///< DelayedTeleopParams::wall_exponent
  double force_noise_N = 0.0;
};

/// 24 cases: round trip {100, 200} ms with 10 % jitter each way, loss {0, 20 %}, wall {300,
/// 1000, 3000} N/m, geometry error and sensor noise {(-1 mm, 0), (+1 mm, 4 mN)}.
std::vector<SetCase> tuning_set();

/// `n` cases from `seed`: round trip U[0, 200] ms, jitter U[0, 50 %] of each way's delay, loss
/// U[0, 20 %], wall log-U[300, 3000] N/m, geometry error U[-1.5, 1.5] mm, noise U[0, 5] mN, and
/// half the walls Hertzian (exponent 1.5), which the tuning set has none of.
/// Throws InvalidParams unless 1 <= n <= 1000.
std::vector<SetCase> validation_set(int n, std::uint64_t seed);

struct SetSummary {
  int cases = 0, settled = 0;
  double worst_handle_excursion_m = 0.0, worst_force_error = 0.0, worst_settling_time_s = 0.0;
  double min_observed_energy_J = 0.0;
  std::vector<SetCase> set;
  std::vector<teleop::DelayCaseResult> results;  ///< in the set's order
};

/// Runs every case of `set` by `scheme` on `base` (its wall stiffness, exponent and noise replaced
/// by the case's). Throws InvalidParams.
SetSummary run_case_set(const teleop::DelayedTeleopParams& base, const std::vector<SetCase>& set,
                        teleop::Scheme scheme);

}  // namespace mc::studies
