#pragma once
/// @file
/// The step length per sawtooth period, s(A, f, direction), of one stick-slip axis, computed from
/// the model at configure time: for every grid point the model runs the sawtooth with the
/// break-away strain z_ba(A, f, direction) of its table (thesis §2.5.2.3, Fig. 2.13; the
/// "generator passes its configuration to the model" of §2.7), and the step is the mean slider
/// displacement per period after a warm-up. This is the model knowledge that schedules the
/// stepping amplitude and frequency (amplitude for a wanted step, frequency for a wanted velocity).

#include <vector>

#include "microcobot/stickslip/actuator.h"

namespace mc::motion {

struct StepMapParams {
  /// The sawtooth amplitudes the map steps the model at ...
  std::vector<double> amplitudes_V = {40, 45, 50, 55, 60, 65, 70, 75, 80, 85, 90, 95, 100};
  /// ... and the frequencies (every pair is one entry of the map).
  std::vector<double> frequencies_Hz = {500, 1000, 2000};
  int warmup_periods = 3;   ///< periods run before measuring (start transient)
  int measure_periods = 6;  ///< periods averaged

  template <class V>
  void visit(V& v) {
    v("amplitudes_V", amplitudes_V);
    v("frequencies_Hz", frequencies_Hz);
    v("warmup_periods", warmup_periods);
    v("measure_periods", measure_periods);
  }
  void validate() const;
};

class StepMap {
 public:
  /// Runs the model on the grid (the only expensive call; allocates).
  StepMap(const stickslip::ActuatorModel& model, const StepMapParams& p = {});

  /// |s| [m] per period at (A, f) in `direction` (bilinear, clamped; 0 where the axis moves the
  /// wrong way or not at all). Never allocates.
  double step_m(double amplitude_V, double frequency_Hz, stickslip::Direction direction) const noexcept;
  /// The smallest amplitude whose step reaches `step_m` at `frequency_Hz` (monotone part of the
  /// map); the largest amplitude when no grid amplitude reaches it. Never allocates.
  double amplitude_for_step(double step_m, double frequency_Hz,
                            stickslip::Direction direction) const noexcept;
  /// The smallest amplitude that gives a step of at least `min_fraction` of the largest one.
  double min_stepping_amplitude_V(double frequency_Hz, stickslip::Direction direction,
                                  double min_fraction = 0.05) const noexcept;
  double max_step_m(double frequency_Hz, stickslip::Direction direction) const noexcept;
  /// Reach [m] at (A, f, direction) (see StepMeasurement; bilinear, clamped). Never allocates.
  double reach_m(double amplitude_V, double frequency_Hz, stickslip::Direction direction) const noexcept;
  /// The largest amplitude whose reach stays below `room_m` (0 when none). Never allocates.
  double amplitude_for_reach(double room_m, double frequency_Hz,
                             stickslip::Direction direction) const noexcept;

  const StepMapParams& params() const { return p_; }
  /// Signed steps [direction][amplitude][frequency] as calibrated (for reports and tests).
  const std::vector<std::vector<double>>& signed_steps(stickslip::Direction d) const {
    return d == stickslip::Direction::kForward ? fwd_raw_ : bwd_raw_;
  }

 private:
  StepMapParams p_;
  std::vector<std::vector<double>> fwd_, bwd_;  ///< |s|, monotone non-decreasing in A (clipped)
  std::vector<std::vector<double>> fwd_raw_, bwd_raw_;
  std::vector<std::vector<double>> fwd_reach_, bwd_reach_;  ///< monotone (running maximum) in A
  double lookup(const std::vector<std::vector<double>>& g, double amplitude_V,
                double frequency_Hz) const noexcept;
};

/// One grid point: the mean signed step per period and the reach, the furthest the slider goes
/// in the drive direction within a period beyond the period's start (>= |step|: the forward slow
/// rise carries it by the PE stroke before the slip, the backward slow fall rings past the end).
struct StepMeasurement {
  double step_m = 0.0;
  double reach_m = 0.0;
};

/// Runs the sawtooth (A, f, direction) from rest and measures it.
StepMeasurement measure_step(const stickslip::ActuatorModel& model, double amplitude_V, double frequency_Hz,
                             stickslip::Direction direction, int warmup_periods, int measure_periods);

}  // namespace mc::motion
