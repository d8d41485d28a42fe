#pragma once
/// @file
/// The drive voltage over one model step, as the amplifier outputs it: a piecewise-linear path
/// from the voltage at the start of the step (the model's state) through `corners` interior
/// corners to `end_V` at the end of the step (docs/concepts/stick-slip.md, "Drive between samples").
///
/// The sawtooth's corners (the start and end of its slew-limited edge, thesis Fig. 2.3) and the
/// step's corner fall anywhere in time, not on the model's grid. Cutting them by sampling
/// (a corner between two samples lost up to ~2 V at 1 V/us) changes the 64/120 kHz ringing
/// the edge excites, and with it the slip: the step size then depended on where the corners fell.
/// A segment carries the corners exactly; the integrator splits its sub-steps at
/// them and evaluates the PI hysteresis at each. A plain sample stream (a DAC played through
/// its reconstruction filter) is a segment without corners: linear between samples.

#include <array>

namespace mc::stickslip {

struct DriveSegment {
  /// At most this many corners per step: two per period of a periodic drive with a period of
  /// at least one step, plus the drive's start (Waveform::segment, simulate() checks the period).
  static constexpr int kMaxCorners = 6;

  int corners = 0;
  std::array<double, kMaxCorners> at{};   ///< corner times as fractions of the step, increasing in (0, 1)
  std::array<double, kMaxCorners> u_V{};  ///< voltage at each corner [V]
  double end_V = 0.0;                     ///< voltage at the end of the step [V]

  /// A segment without corners: linear from the present voltage to `u_V` (a sample stream).
  static DriveSegment to(double u_V) noexcept {
    DriveSegment s;
    s.end_V = u_V;
    return s;
  }
  /// Appends a corner at fraction `at` (ignored if not after the last one or beyond the capacity).
  void add_corner(double at_fraction, double u) noexcept {
    if (corners >= kMaxCorners || !(at_fraction > 0.0 && at_fraction < 1.0)) return;
    if (corners > 0 && at_fraction <= at[static_cast<std::size_t>(corners - 1)]) return;
    at[static_cast<std::size_t>(corners)] = at_fraction;
    u_V[static_cast<std::size_t>(corners)] = u;
    ++corners;
  }
};

}  // namespace mc::stickslip
