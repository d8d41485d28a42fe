#include "microcobot/studies/integrator_accuracy.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"
#include "microcobot/core/rng.h"

namespace mc::studies {

namespace {
/// A drive whose net step is below this fraction of its slider's range does not step (creep, a
/// sine, a backward drive whose two slips nearly cancel): its step error is judged against it.
constexpr double kStepFloorOfRange = 0.1;
}  // namespace

std::vector<AccuracyDrive> accuracy_drives(int n, std::uint64_t seed, const stickslip::DriveParams& limits) {
  require(n >= 1, "drives", "must be >= 1", n);
  Rng rng(seed);
  std::vector<AccuracyDrive> out;
  out.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double pick = rng.uniform();
    const stickslip::WaveKind kind =
        pick < 0.7 ? stickslip::WaveKind::kSawtooth
                   : (pick < 0.85 ? stickslip::WaveKind::kSine : stickslip::WaveKind::kStep);
    const double amplitude = rng.uniform(10.0, std::min(100.0, limits.max_V - limits.min_V));
    const double frequency = 20.0 * std::pow(100.0, rng.uniform());  // log-uniform 20..2000 Hz
    const stickslip::Direction direction =
        rng.uniform() < 0.5 ? stickslip::Direction::kForward : stickslip::Direction::kBackward;
    AccuracyDrive d;
    d.wave = stickslip::make_waveform(kind, amplitude, frequency, direction, limits, limits.min_V);
    // The power-up period, then at least three at the steady state (at least 3 ms).
    d.duration_s = kind == stickslip::WaveKind::kStep ? 5e-3 : std::max(4.0 / frequency, 3e-3);
    out.push_back(d);
  }
  return out;
}

DriveAccuracy check_drive(const stickslip::ActuatorModel& model, const AccuracyDrive& drive,
                          const stickslip::ReferenceOptions& options) {
  stickslip::ReferenceOptions o = options;
  o.sample_dt_s = model.dt_s();
  stickslip::Trajectory fixed = simulate(model, drive.wave, drive.duration_s);
  stickslip::Trajectory ref = stickslip::simulate_reference(model.params(), drive.wave, drive.duration_s, o);
  const std::size_t n = std::min(fixed.x2_m.size(), ref.x2_m.size());
  DriveAccuracy r;
  const auto [lo, hi] = std::minmax_element(ref.x2_m.begin(), ref.x2_m.begin() + static_cast<long>(n));
  r.range_m = *hi - *lo;
  require(r.range_m > 0.0, "drive", "the reference slider does not move");
  double sq = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double e = fixed.x2_m[i] - ref.x2_m[i];
    sq += e * e;
    r.max_error = std::max(r.max_error, std::abs(e));
  }
  r.rms_error = std::sqrt(sq / static_cast<double>(n)) / r.range_m;
  r.max_error /= r.range_m;
  // Net motion per period over the whole periods after the first (same phase to same phase; the
  // first holds the power-up transient), x interpolated at t = kT on the common grid.
  const double dt = model.dt_s();
  auto at = [&](const stickslip::Trajectory& tr, double t) {
    const std::size_t k = std::min(n - 2, static_cast<std::size_t>(t / dt));
    const double f = std::clamp((t - tr.t_s[k]) / (tr.t_s[k + 1] - tr.t_s[k]), 0.0, 1.0);
    return tr.x2_m[k] + f * (tr.x2_m[k + 1] - tr.x2_m[k]);
  };
  if (drive.wave.kind == stickslip::WaveKind::kStep) {
    r.step_m = fixed.x2_m[n - 1] - fixed.x2_m[0];
    r.step_ref_m = ref.x2_m[n - 1] - ref.x2_m[0];
  } else {
    const double period = 1.0 / drive.wave.frequency_Hz;
    const double periods = std::floor(drive.duration_s / period + 1e-9);
    require(periods >= 2.0, "duration_s", "must hold at least two whole periods of the drive",
            drive.duration_s);
    r.steady_periods = static_cast<int>(periods) - 1;
    r.first_period_m = at(fixed, period) - fixed.x2_m[0];
    r.first_period_ref_m = at(ref, period) - ref.x2_m[0];
    r.step_m = (at(fixed, periods * period) - at(fixed, period)) / (periods - 1.0);
    r.step_ref_m = (at(ref, periods * period) - at(ref, period)) / (periods - 1.0);
  }
  r.step_error =
      std::abs(r.step_m - r.step_ref_m) / std::max(std::abs(r.step_ref_m), kStepFloorOfRange * r.range_m);
  r.model = std::move(fixed);
  r.reference = std::move(ref);
  return r;
}

}  // namespace mc::studies
