#pragma once
/// @file
/// The break-away elastic strain z_ba as a function of the sawtooth's amplitude, frequency and
/// direction (thesis §2.5.2.3, Fig. 2.13, §2.6): a table on an (amplitude x frequency) grid per
/// direction, clamped at the edges, so that identification can replace it with measured
/// values. In between it is bilinear in (amplitude, log frequency): z_ba is affine in the amplitude
/// (Fig. 2.13) and varies with the frequency on a logarithmic scale (§2.8: "mainly depends on the
/// voltage amplitude and less on the voltage frequency"; the grids span decades, 50 Hz..2 kHz),
/// so a surface affine in log f is reproduced exactly between grid columns. z_ss = z_ba / (z_ba/|z_ss|) with
/// the ratio of Table 2.8.

#include <vector>

namespace mc::stickslip {

/// Drive direction (thesis Fig. 2.3): forward = slow rise + abrupt drop.
enum class Direction { kForward, kBackward };

struct BreakawayTable {
  std::vector<double> amplitudes_V;             ///< grid rows, strictly increasing
  std::vector<double> frequencies_Hz;           ///< grid columns, strictly increasing, > 0
  std::vector<std::vector<double>> forward_m;   ///< z_ba(+) [row = amplitude][col = frequency]
  std::vector<std::vector<double>> backward_m;  ///< z_ba(-)

  template <class V>
  void visit(V& v) {
    v("amplitudes_V", amplitudes_V);
    v("frequencies_Hz", frequencies_Hz);
    v("forward_m", forward_m);
    v("backward_m", backward_m);
  }
  void validate() const;

  /// z_ba [m] at (amplitude, frequency, direction): bilinear in (amplitude, log frequency),
  /// clamped to the grid. No allocation.
  double lookup(double amplitude_V, double frequency_Hz, Direction direction) const noexcept;
};

/// The default surface (the thesis gives no values: chosen, docs/parameters.md): z_ba grows affinely with the
/// amplitude (the shape of Fig. 2.13), a little less with frequency (§2.8: "mainly depends on the
/// voltage amplitude and less on the voltage frequency"), and is larger backward than forward
/// (the asymmetry of Fig. 2.15-2.16).
BreakawayTable default_breakaway_table();

}  // namespace mc::stickslip
