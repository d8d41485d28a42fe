#pragma once
/// @file
/// Reference solution of the same continuous model (eq. 2.1-2.21) by Boost.odeint's adaptive
/// Dormand-Prince 5(4) at tight tolerance: the yardstick of the fixed-step integrator's error
/// (docs/benchmarks.md). The PI operators are committed at every output sample and evaluated
/// from the committed state inside the interval (exact while U is monotone in the interval).
/// End stops are not modelled here (the experiments stay far from them).

#include <vector>

#include "microcobot/stickslip/actuator.h"

namespace mc::stickslip {

struct ReferenceOptions {
  double rel_tol = 1e-9;
  double abs_tol_m = 1e-15;   ///< absolute tolerance on positions/strains (velocities: / 1 us)
  double sample_dt_s = 1e-5;  ///< output grid (the fixed-step model's dt, for a direct comparison)
};

/// Runs `wave` for `duration_s` from rest; returns samples every sample_dt_s (t, U, x1, x2).
/// Throws mc::ComputationFailed if the solution becomes NaN/Inf.
Trajectory simulate_reference(const StickSlipParams& params, const Waveform& wave, double duration_s,
                              const ReferenceOptions& options = {});

/// RMS of (a.x2 - b.x2) over the common samples divided by the range of b.x2 (b = reference).
double relative_rms_error(const Trajectory& a, const Trajectory& b);

}  // namespace mc::stickslip
