#pragma once
/// @file
/// The lag compensator of the virtual-environment loop (thesis section 4.5.3, Fig. 4.27):
/// C(s) = (1 + s / w_z) / (1 + s / w_p) with w_p < w_z, both below the 100 Hz bandwidth, so that
/// the rendered force keeps its static gain (the operator feels the full stiffness) while the
/// high band, where the 150 Hz mode and the sampling delay make the wall chatter, is attenuated by
/// w_p / w_z without phase loss there. Discretized by Tustin at the controller rate (dsp::c2d).

#include "microcobot/dsp/sos.h"

namespace mc::tweezers {

class LagCompensator {
 public:
  /// Throws InvalidParams unless 0 < pole_Hz < zero_Hz < rate_Hz / 2.
  LagCompensator(double pole_Hz, double zero_Hz, double rate_Hz);
  /// One sample of the compensated signal. Never allocates.
  double process(double x) { return filter_.process(x); }
  void reset() { filter_.reset(); }
  /// High-frequency gain w_p / w_z.
  double high_frequency_gain() const { return pole_Hz_ / zero_Hz_; }
  /// Discrete-time response magnitude at f [Hz].
  double magnitude(double f_Hz) const;
  /// Discrete-time response phase [rad] at f [Hz].
  double phase(double f_Hz) const;

 private:
  double pole_Hz_, zero_Hz_, rate_Hz_;
  dsp::SosFilter filter_;
};

}  // namespace mc::tweezers
