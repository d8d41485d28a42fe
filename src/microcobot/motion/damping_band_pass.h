#pragma once
/// @file
/// The tracking controller's band-pass on the measured position (tracking_controller.h,
/// TrackingParams::damp_gain): a second-order band-pass of constant 0 dB peak gain (RBJ audio-EQ
/// cookbook), normalised by a0,
///   y[n] = b0 (x[n] - x[n-2]) - a1 y[n-1] - a2 y[n-2],
///   b0 = alpha / (1 + alpha), a1 = -2 cos(w0) / (1 + alpha), a2 = (1 - alpha) / (1 + alpha),
///   w0 = 2 pi f0 / fs, alpha = sin(w0) / (2 Q),
/// started at rest on its first input (the input's history is that input, the output's zero), so
/// that a position far from zero does not ring it. Never allocates; noexcept.

#include <cmath>
#include <numbers>

namespace mc::motion {

class DampingBandPass {
 public:
  DampingBandPass(double f0_Hz, double q, double rate_Hz) noexcept {
    const double w0 = 2.0 * std::numbers::pi * f0_Hz / rate_Hz;
    const double alpha = std::sin(w0) / (2.0 * q);
    b0_ = alpha / (1.0 + alpha);
    a1_ = -2.0 * std::cos(w0) / (1.0 + alpha);
    a2_ = (1.0 - alpha) / (1.0 + alpha);
  }
  /// At rest again: the next input starts it.
  void reset() noexcept { started_ = false; }
  /// One sample in, y[n] out.
  double step(double x) noexcept {
    if (!started_) {
      x1_ = x2_ = x;
      y1_ = y2_ = 0.0;
      started_ = true;
    }
    const double y = b0_ * (x - x2_) - a1_ * y1_ - a2_ * y2_;
    x2_ = x1_;
    x1_ = x;
    y2_ = y1_;
    y1_ = y;
    return y;
  }
  /// y[n-1], after step() returned y[n].
  double previous() const noexcept { return y2_; }

 private:
  double b0_ = 0.0, a1_ = 0.0, a2_ = 0.0;
  double x1_ = 0.0, x2_ = 0.0, y1_ = 0.0, y2_ = 0.0;
  bool started_ = false;
};

}  // namespace mc::motion
