#pragma once
/// @file
/// What one edge of the sawtooth costs in position, per direction, as the tracking controller
/// learns it (tracking_controller.h): during the fast edge the slider slips with the piezo and
/// is dragged back by the backslip b. The controller anchors its ramp where the slider should land,
///   x_after = x_edge - b (forward), x_edge + b (backward),
/// and once the edge has settled the miss it measures refines that direction's estimate,
///   b <- max(0, b + k_b miss)  (miss counted along the edge's direction).
/// The power-up's ramp-in is not a step: it lands with b = 0 and teaches nothing.
/// Never allocates; noexcept.

#include <algorithm>

namespace mc::motion {

class BackslipEstimate {
 public:
  /// The starting estimates [m] (the model's prediction, or a fixed value).
  void set(double forward_m, double backward_m) noexcept {
    forward_m_ = forward_m;
    backward_m_ = backward_m;
  }
  double of(bool forward) const noexcept { return forward ? forward_m_ : backward_m_; }

  /// An edge starts with the slider at `x_m`, expecting this direction's estimate.
  void edge_at(double x_m, bool forward) noexcept { edge_at(x_m, forward, of(forward)); }
  /// ... expecting `backslip_m` (the power-up's ramp-in: none).
  void edge_at(double x_m, bool forward, double backslip_m) noexcept {
    x_edge_m_ = x_m;
    forward_ = forward;
    used_m_ = backslip_m;
  }
  /// Where the slider should be once the edge is over.
  double landing_m() const noexcept { return x_edge_m_ + (forward_ ? -used_m_ : used_m_); }
  /// The edge's outcome is awaited (from the anchor until it has settled).
  void await_outcome() noexcept { awaiting_ = true; }
  bool awaiting_outcome() const noexcept { return awaiting_; }
  /// The edge's miss measured (the anchor was off by `miss_m`): with `learns`, the estimate of
  /// its direction refined with `gain`.
  void settle(double miss_m, double gain, bool learns) noexcept {
    awaiting_ = false;
    if (!learns) return;
    double& b = forward_ ? forward_m_ : backward_m_;
    b = std::max(0.0, b + gain * (forward_ ? miss_m : -miss_m));
  }
  /// No outcome awaited (a reset).
  void forget_outcome() noexcept { awaiting_ = false; }

 private:
  double forward_m_ = 0.0, backward_m_ = 0.0;
  double x_edge_m_ = 0.0, used_m_ = 0.0;
  bool forward_ = true, awaiting_ = false;
};

}  // namespace mc::motion
