#include "microcobot/motion/pid.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::motion {

void PidParams::validate() const {
  require_non_negative(kp, "pid.kp");
  require_non_negative(ki, "pid.ki");
  require_non_negative(kd, "pid.kd");
  require_non_negative(derivative_filter_s, "pid.derivative_filter_s");
  require(std::isfinite(out_min) && std::isfinite(out_max) && out_min < out_max, "pid.out_max",
          "must be > pid.out_min", out_max);
}

Pid::Pid(const PidParams& p) : p_(p) { p_.validate(); }

void Pid::reset(double integral) noexcept {
  i_ = integral;
  e_prev_ = 0.0;
  d_ = 0.0;
  first_ = true;
}

double Pid::update(double error, double dt_s, double feedforward, bool freeze) noexcept {
  if (!first_ && p_.kd > 0.0) {
    const double raw = (error - e_prev_) / dt_s;
    const double a = p_.derivative_filter_s > 0.0 ? dt_s / (p_.derivative_filter_s + dt_s) : 1.0;
    d_ += a * (raw - d_);
  }
  first_ = false;
  e_prev_ = error;
  const double unsat = feedforward + p_.kp * error + i_ + p_.kd * d_;
  const double out = std::clamp(unsat, p_.out_min, p_.out_max);
  const bool pushing_high = unsat >= p_.out_max && error > 0.0;
  const bool pushing_low = unsat <= p_.out_min && error < 0.0;
  if (!freeze && !pushing_high && !pushing_low) i_ += p_.ki * error * dt_s;
  return out;
}

}  // namespace mc::motion
