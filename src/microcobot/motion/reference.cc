#include "microcobot/motion/reference.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "microcobot/core/error.h"

namespace mc::motion {

void MotionLimits::validate() const {
  require_positive(max_velocity_m_s, "limits.max_velocity_m_s");
  require_positive(max_acceleration_m_s2, "limits.max_acceleration_m_s2");
}

ReferenceLimiter::ReferenceLimiter(const MotionLimits& limits, double x0_m) : lim_(limits) {
  lim_.validate();
  s_.x_m = x0_m;
}

ReferenceSample ReferenceLimiter::step(double setpoint_m, double dt_s) noexcept {
  const double e = setpoint_m - s_.x_m;
  const double a = lim_.max_acceleration_m_s2;
  // Velocity that still stops on the setpoint, accounting for the discrete step.
  const double brake =
      std::sqrt(std::max(0.0, 2.0 * a * std::abs(e) + 0.25 * a * a * dt_s * dt_s)) - 0.5 * a * dt_s;
  double v_cmd = std::copysign(std::min(lim_.max_velocity_m_s, brake), e);
  if (std::abs(e) < 1e-15) v_cmd = 0.0;
  const double dv = std::clamp(v_cmd - s_.v_m_s, -a * dt_s, a * dt_s);
  const double v_new = s_.v_m_s + dv;
  // x advances by v_new dt: with the discrete braking velocity above, the reference reaches the
  // setpoint without crossing it; it lands exactly when the last step would reach it.
  const double x_new = s_.x_m + v_new * dt_s;
  if ((setpoint_m - x_new) * e <= 0.0) {
    // On the setpoint; the velocity decays at the acceleration limit (at most a step or two).
    const double v_land = std::abs(s_.v_m_s) <= a * dt_s * (1.0 + 1e-9) ? 0.0 : v_new;
    s_ = ReferenceSample{setpoint_m, v_land, (v_land - s_.v_m_s) / dt_s};
    return s_;
  }
  s_ = ReferenceSample{x_new, v_new, dv / dt_s};
  return s_;
}

SineReference::SineReference(double x0_m, double amplitude_m, double frequency_Hz, const MotionLimits& limits)
    : x0_(x0_m), a_(amplitude_m), w_(2.0 * std::numbers::pi * frequency_Hz) {
  limits.validate();
  require_positive(frequency_Hz, "sine.frequency_Hz");
  require(std::isfinite(amplitude_m), "sine.amplitude_m", "must be finite", amplitude_m);
  require(std::abs(a_) * w_ <= limits.max_velocity_m_s * (1.0 + 1e-9), "sine.amplitude_m",
          "peak velocity A 2 pi f exceeds limits.max_velocity_m_s", std::abs(a_) * w_);
  require(std::abs(a_) * w_ * w_ <= limits.max_acceleration_m_s2 * (1.0 + 1e-9), "sine.amplitude_m",
          "peak acceleration A (2 pi f)^2 exceeds limits.max_acceleration_m_s2", std::abs(a_) * w_ * w_);
}

ReferenceSample SineReference::at(double t) const noexcept {
  return {x0_ + a_ * std::sin(w_ * t), a_ * w_ * std::cos(w_ * t), -a_ * w_ * w_ * std::sin(w_ * t)};
}

double trapezoid_duration_s(double distance_m, const MotionLimits& limits) {
  limits.validate();
  const double d = std::abs(distance_m), v = limits.max_velocity_m_s, a = limits.max_acceleration_m_s2;
  if (d >= v * v / a) return d / v + v / a;  // trapezoid: accelerate, cruise, decelerate
  return 2.0 * std::sqrt(d / a);             // triangle
}

}  // namespace mc::motion
