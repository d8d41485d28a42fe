#pragma once
/// @file
/// Cascades of second-order sections (biquads) run in transposed direct form II, the form
/// scipy.signal.sosfilt uses. Construction allocates; filtering never does.

#include <array>
#include <span>
#include <vector>

namespace mc::dsp {

/// One second-order section b0 + b1 z^-1 + b2 z^-2 over 1 + a1 z^-1 + a2 z^-2 (a0 = 1).
struct Biquad {
  double b0 = 1.0, b1 = 0.0, b2 = 0.0;
  double a1 = 0.0, a2 = 0.0;

  /// From scipy's row layout [b0, b1, b2, a0, a1, a2]; normalises by a0 (must be non-zero).
  static Biquad from_row(const std::array<double, 6>& row);
  /// scipy's row layout [b0, b1, b2, 1, a1, a2].
  std::array<double, 6> row() const { return {b0, b1, b2, 1.0, a1, a2}; }
};

/// A cascade of biquads in series (scipy's `sos` array).
using Sos = std::vector<Biquad>;

/// A filter running a cascade of biquads, transposed direct form II (two states per
/// section). Numerically sound in double precision down to fc/fs = 1e-4 (the
/// transposed form keeps the states at the signal's scale; tested in sos_test.cc).
class SosFilter {
 public:
  /// Takes the sections (allocates once). Throws InvalidParams if `sections` is empty or
  /// holds a non-finite coefficient.
  explicit SosFilter(Sos sections);

  /// Filters one sample. Never allocates.
  double process(double x) {
    for (std::size_t i = 0; i < sections_.size(); ++i) {
      const Biquad& s = sections_[i];
      double* z = &state_[2 * i];
      const double y = s.b0 * x + z[0];
      z[0] = s.b1 * x - s.a1 * y + z[1];
      z[1] = s.b2 * x - s.a2 * y;
      x = y;
    }
    return x;
  }

  /// Filters a block; `out` must have in.size() elements and may alias `in`. Never allocates.
  /// A cascade of two or more sections runs in groups of two to eight sections as wavefronts
  /// (section g on sample k - g, so that their dependency chains overlap): bit-identical to
  /// calling process(double) on each sample. A lone section runs a four-sample look-ahead of its
  /// state-space form instead (sos.cc): equal to process(double) up to rounding, and the filter
  /// state stays the same TDF-II pair, so block and per-sample calls can be mixed.
  void process(std::span<const double> in, std::span<double> out);

  /// Zeroes the states (the filter then responds as if the input had always been 0).
  void reset();
  /// Sets the states to the steady state for a constant input `x` (scipy's sosfilt_zi * x).
  void reset_to_steady_state(double x);

  const Sos& sections() const { return sections_; }
  std::size_t size() const { return sections_.size(); }

 private:
  Sos sections_;
  std::vector<double> state_;  // 2 per section: z1, z2
};

/// Filters `x` with `sos` from zero initial state (scipy.signal.sosfilt(sos, x)).
std::vector<double> sosfilt(const Sos& sos, std::span<const double> x);

}  // namespace mc::dsp
