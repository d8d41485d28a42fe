#pragma once
/// @file
/// Drive voltages of the stick-slip actuator (thesis §2.2.2, Fig. 2.3): sawtooth (forward: slow
/// rise, abrupt drop; backward: abrupt rise, slow drop), sine and step, each an analytic function
/// of time whose abrupt edges last amplitude / slew rate (the amplifier's slew limit). Voltages
/// are limited to the amplifier's 0-100 V (thesis §2.3); a waveform beyond throws.

#include <string>

#include "microcobot/stickslip/breakaway_table.h"
#include "microcobot/stickslip/drive_segment.h"

namespace mc::stickslip {

enum class WaveKind { kSawtooth, kSine, kStep };

/// Amplifier limits.
struct DriveParams {
  double slew_rate_V_s = 1.0e6;  ///< slew limit of the HV amplifier: 1 V/us (erratum 7, docs/errata.md)
  double min_V = 0.0;            ///< amplifier output range (thesis §2.3: 100 V maximum)
  double max_V = 100.0;          ///< (its upper end)

  template <class V>
  void visit(V& v) {
    v("slew_rate_V_s", slew_rate_V_s);
    v("min_V", min_V);
    v("max_V", max_V);
  }
  void validate() const;
};

/// One waveform. U(t) = offset + shape(t) with shape in [0, amplitude].
struct Waveform {
  WaveKind kind = WaveKind::kSawtooth;
  double amplitude_V = 40.0;
  double frequency_Hz = 50.0;  ///< ignored by kStep
  Direction direction = Direction::kForward;
  double offset_V = 0.0;
  double slew_rate_V_s = 1.0e6;

  /// Throws mc::InvalidParams if the voltage leaves [min_V, max_V], or if the abrupt edge
  /// (amplitude / slew) does not fit in a period.
  void validate(const DriveParams& limits) const;
  /// U(t) [V]. Never allocates.
  double value(double t) const noexcept;
  /// U over [t0, t0 + h] as the model takes it: every corner inside the interval (the drive's
  /// start at t = 0; the sawtooth's period start and the top of each edge; the step's end of
  /// edge; the sine's extrema, where U turns and the PI hysteresis branches) and U(t0 + h).
  /// At most DriveSegment::kMaxCorners corners: h must not exceed the period. Never allocates.
  DriveSegment segment(double t0, double h) const noexcept;
  /// Duration of the abrupt edge [s].
  double edge_time_s() const noexcept { return amplitude_V / slew_rate_V_s; }
};

/// A waveform with the amplifier's slew rate.
Waveform make_waveform(WaveKind kind, double amplitude_V, double frequency_Hz, Direction direction,
                       const DriveParams& limits, double offset_V = 0.0);

WaveKind parse_wave_kind(const std::string& name);   ///< "sawtooth" | "sine" | "step", else UsageError
Direction parse_direction(const std::string& name);  ///< "forward" | "backward", else UsageError
std::string to_string(Direction d);
std::string to_string(WaveKind k);

}  // namespace mc::stickslip
