#pragma once
/// @file
/// A correction caught up smoothly (tracking_controller.h, after each edge): the offset moves
/// from where it was to its goal along a raised cosine,
///   c(s) = c_from + (c_to - c_from) (1 - cos(pi s)) / 2,   s = t / T clamped to [0, 1],
/// whose slope is zero at both ends, so that the reference's plan never steps in velocity. A miss
/// measured on the way adds to the goal and starts a second cosine from where the offset is.
/// Never allocates; noexcept.

#include <cmath>
#include <numbers>

namespace mc::motion {

class CatchUp {
 public:
  /// Raised cosine from 0 (s <= 0) to 1 (s >= 1).
  static double blend(double s) noexcept {
    if (s <= 0.0) return 0.0;
    if (s >= 1.0) return 1.0;
    return 0.5 - 0.5 * std::cos(std::numbers::pi * s);
  }
  /// Nothing to catch up.
  void reset() noexcept { from_ = now_ = to_ = 0.0; }
  /// From zero now to `to`.
  void restart(double to) noexcept {
    from_ = now_ = 0.0;
    to_ = to;
  }
  /// The offset at the fraction `s` of the catch-up's time.
  double update(double s) noexcept {
    now_ = from_ + (to_ - from_) * blend(s);
    return now_;
  }
  /// A miss measured: added to the goal, caught up from where the offset is.
  void add(double miss) noexcept {
    from_ = now_;
    to_ += miss;
  }
  double now() const noexcept { return now_; }
  /// What is still to be caught up.
  double remaining() const noexcept { return to_ - now_; }

 private:
  double from_ = 0.0, now_ = 0.0, to_ = 0.0;
};

}  // namespace mc::motion
