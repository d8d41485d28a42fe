#include "microcobot/teleop/rotary_target.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::teleop {

RotaryTarget::RotaryTarget(const motion::RotaryAxisParams& params, double dt_s, double start_rad,
                           double min_rad, double max_rad)
    : p_(params), dt_s_(dt_s), target_(start_rad), min_(min_rad), max_(max_rad), raw_(start_rad) {
  p_.validate();
  require_positive(dt_s, "dt_s");
  require(min_rad < max_rad && start_rad >= min_rad && start_rad <= max_rad, "rotary.start_rad",
          "must lie within the axis' travel", start_rad);
}

void RotaryTarget::tick(const ConsoleInput& c) noexcept {
  velocity_ = 0.0;
  const double step = p_.max_speed_rad_s * dt_s_;
  stop_level_ += std::clamp((stop_on_ ? stop_goal_level_ : 0.0) - stop_level_, -level_rate_ * dt_s_,
                            level_rate_ * dt_s_);
  if (!(c.deadman && c.fresh)) {  // nothing moves without the deadman; the dial starts again from here
    raw_ = target_;
    return;
  }
  const double limit = p_.max_speed_rad_s;
  double next = target_;
  if (c.has_theta_goal && std::isfinite(c.theta_goal_rad)) {
    const double speed =
        std::isfinite(c.theta_speed_rad_s) ? std::clamp(c.theta_speed_rad_s, 0.0, limit) : 0.0;
    const double goal = std::clamp(c.theta_goal_rad, min_, max_);
    next = target_ + std::clamp(goal - target_, -speed * dt_s_, speed * dt_s_);
    raw_ = next;
  } else if (std::isfinite(c.theta_rate_rad_s)) {
    raw_ = std::clamp(raw_ + std::clamp(c.theta_rate_rad_s, -limit, limit) * dt_s_, min_, max_);
    double want = raw_;
    if (stop_level_ > 0.0) {
      const double e = raw_ - stop_rad_, h = capture_rad_;
      const double w = std::clamp((2.0 * h - std::abs(e)) / h, 0.0, 1.0);
      want = std::clamp(stop_rad_ + (1.0 - stop_level_ * w) * e, min_, max_);
    }
    next = target_ + std::clamp(want - target_, -step, step);
  }
  velocity_ = (next - target_) / dt_s_;
  target_ = next;
}

void RotaryTarget::set_stop(bool on, double stop_rad, double level, double capture_rad,
                            double level_rate_1_s) noexcept {
  const bool valid = std::isfinite(stop_rad) && std::isfinite(level) && level >= 0.0 && level <= 1.0 &&
                     std::isfinite(capture_rad) && capture_rad > 0.0 && std::isfinite(level_rate_1_s) &&
                     level_rate_1_s > 0.0;
  on = on && valid;
  if (on && (!stop_on_ || stop_rad != stop_rad_)) stop_level_ = 0.0;  // a new stop fades in
  stop_on_ = on;
  if (!on) return;
  stop_rad_ = stop_rad;
  stop_goal_level_ = level;
  capture_rad_ = capture_rad;
  level_rate_ = level_rate_1_s;
}

void RotaryTarget::hold_at(double measured_rad) noexcept {
  if (std::isfinite(measured_rad)) target_ = std::clamp(measured_rad, min_, max_);
  raw_ = target_;
  velocity_ = 0.0;
}

}  // namespace mc::teleop
