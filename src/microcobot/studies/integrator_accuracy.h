#pragma once
/// @file
/// The fixed-step integrator's accuracy against the reference solver (reference_solver.h), both
/// driven by the exact waveform, over drives drawn at random across the operating range:
/// slider RMS and max error as fractions of the slider's range, and the net step
/// per period. The drives' corners fall anywhere in time, so the study measures what the
/// model does between its grid points, not only on drives aligned with it.

#include <cstdint>
#include <vector>

#include "microcobot/stickslip/actuator.h"
#include "microcobot/stickslip/reference_solver.h"

namespace mc::studies {

/// One drive of the study and how long it runs.
struct AccuracyDrive {
  stickslip::Waveform wave;
  double duration_s = 0.0;
};

/// `n` drives drawn with a seeded generator (the same set on every machine): 70 % sawtooth
/// (amplitude uniform in [10, 100] V, frequency log-uniform in [20, 2000] Hz, either direction),
/// 15 % sine, 15 % step (amplitude in [10, 100] V). Periodic drives run 4 periods (the power-up
/// period and three at the steady state; at least 3 ms), steps 5 ms.
std::vector<AccuracyDrive> accuracy_drives(int n, std::uint64_t seed, const stickslip::DriveParams& limits);

struct DriveAccuracy {
  double rms_error = 0.0;  ///< RMS of (x2 - x2_ref) / range of x2_ref
  double max_error = 0.0;  ///< max |x2 - x2_ref| / range of x2_ref
  double range_m = 0.0;    ///< range of the reference's slider position
  /// Net slider motion per period (periodic drives: over the whole periods after the first, same
  /// phase to same phase) or over the run (step), by the model and by the reference [m].
  double step_m = 0.0, step_ref_m = 0.0;
  /// Periodic drives: the first period's (power-up) displacement, model and reference [m], and
  /// the number of periods step_m is the mean of.
  double first_period_m = 0.0, first_period_ref_m = 0.0;
  int steady_periods = 0;
  /// |step - step_ref| / max(|step_ref|, 0.1 range_m): a drive that does not step (its net step
  /// below a tenth of its range: creep below the threshold, a sine, a backward drive whose two
  /// slips nearly cancel) is judged against a tenth of its range, not against ~0.
  double step_error = 0.0;
  stickslip::Trajectory model, reference;  ///< both runs on the model's grid
};

/// Runs `drive` through `model` (its default step) and through the reference solver sampled on
/// the model's grid. Throws mc::ComputationFailed if either diverges.
DriveAccuracy check_drive(const stickslip::ActuatorModel& model, const AccuracyDrive& drive,
                          const stickslip::ReferenceOptions& options = {});

}  // namespace mc::studies
