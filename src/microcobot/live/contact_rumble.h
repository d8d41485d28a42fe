#pragma once
/// @file
/// The console's vibrotactile channel: the high band of the contact force, as the dual-stage
/// haptic interface's crossover splits it (thesis ch. 3: the low band to the force-feedback
/// stage, the high band to the vibrotactile one). Each axis of the contact force, sampled at the
/// telemetry's rate, goes through a 4th-order Linkwitz-Riley high-pass at the crossover; the
/// rumble of one console frame is the RMS of the three high bands over the samples since the last
/// frame, scaled so that `full_scale_N` is 1 and clipped there. Runs on the telemetry's drain
/// thread; never allocates after construction.

#include <array>
#include <cstddef>

#include "microcobot/dsp/sos.h"

namespace mc::live {

class ContactRumble {
 public:
  /// Throws mc::InvalidParams from the filter's design (crossover within (0, rate/2)).
  ContactRumble(double crossover_Hz, double rate_Hz, double full_scale_N);
  /// One telemetry sample of the contact force [N] (non-finite components count as 0).
  void add(double fx_N, double fy_N, double fz_N) noexcept;
  /// The rumble in [0, 1] over the samples added since the last call (0 without any).
  double take() noexcept;

 private:
  std::array<dsp::SosFilter, 3> high_;
  double full_scale_N_;
  double sum_ = 0.0;
  std::size_t n_ = 0;
};

}  // namespace mc::live
