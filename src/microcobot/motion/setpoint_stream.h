#pragma once
/// @file
/// Setpoint streaming: position setpoints arrive at about 1 kHz (from the
/// teleoperation coupling, the console, the network link or Python), each stamped with the
/// sender's time. The controller reads the stream at its own rate, `delay_s` behind the newest
/// stamp's clock (a bounded look-ahead: the interpolation sees at most `capacity` setpoints and
/// never waits longer than `delay_s`), linearly interpolated between the two setpoints around
/// t - delay. Late or missing setpoints hold: beyond the newest setpoint the output stays on it
/// (no extrapolation), and the output is rate limited so that a late setpoint that arrives after
/// a hold is joined at `max_velocity_m_s`, never by a jump (a stream that stays within the limit
/// passes unchanged: no lag beyond the look-ahead). push() and sample() never allocate (a ring of `capacity`
/// entries made at construction).

#include <cstddef>
#include <vector>

#include "microcobot/motion/reference.h"

namespace mc::motion {

struct SetpointStreamParams {
  double delay_s = 2e-3;           ///< look-ahead: the output lags the setpoints by this much
  int capacity = 32;               ///< setpoints kept (>= delay / period + 2)
  double max_velocity_m_s = 1e-3;  ///< rate limit of the output (rejoining after a hold)

  template <class V>
  void visit(V& v) {
    v("delay_s", delay_s);
    v("capacity", capacity);
    v("max_velocity_m_s", max_velocity_m_s);
  }
  void validate() const;
};

class SetpointStream {
 public:
  /// Starts holding `x0_m`. Allocates the ring here only.
  explicit SetpointStream(const SetpointStreamParams& p = {}, double x0_m = 0.0);
  /// A setpoint stamped `stamp_s` (sender's clock). Out-of-order or non-finite ones are dropped
  /// (returns false). Never allocates.
  bool push(double stamp_s, double x_m) noexcept;
  /// The reference at controller time `t_s` (same clock as the stamps), advanced by `dt_s`.
  /// Never allocates.
  ReferenceSample sample(double t_s, double dt_s) noexcept;
  /// True when the last sample() held the newest setpoint because later ones were missing.
  bool holding() const noexcept { return holding_; }
  std::size_t size() const noexcept { return count_; }
  void reset(double x0_m) noexcept;

 private:
  struct Entry {
    double t = 0.0, x = 0.0;
  };
  ReferenceSample follow(double x_m, double dt_s) noexcept;
  const Entry& at(std::size_t i) const noexcept { return ring_[(head_ + i) % ring_.size()]; }
  SetpointStreamParams p_;
  std::vector<Entry> ring_;
  std::size_t head_ = 0, count_ = 0;
  ReferenceSample out_;
  bool holding_ = false;
};

}  // namespace mc::motion
