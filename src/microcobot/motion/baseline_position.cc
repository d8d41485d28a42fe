#include "microcobot/motion/baseline_position.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::motion {

std::string to_string(BaselineKind k) {
  return k == BaselineKind::kOpenLoopCounting ? "open-loop step counting" : "thesis PID (stepping only)";
}

void BaselinePositionParams::validate() const {
  require_positive(frequency_Hz, "baseline.frequency_Hz");
  require_in_range(nominal_amplitude_V, 0.0, 100.0, "baseline.nominal_amplitude_V");
  require_positive(nominal_step_m, "baseline.nominal_step_m");
  pid.validate();
  require_non_negative(deadband_m, "baseline.deadband_m");
}

BaselinePositionController::BaselinePositionController(const BaselinePositionParams& p, BaselineKind kind,
                                                       double slew_rate_V_s)
    : p_(p), kind_(kind), pid_(p.pid), gen_(slew_rate_V_s) {
  p_.validate();
}

void BaselinePositionController::set_target(double target_m, double start_m) noexcept {
  target_ = target_m;
  const double d = target_m - start_m;
  const Direction dir = d >= 0.0 ? Direction::kForward : Direction::kBackward;
  pid_.reset();
  last_sign_ = 0.0;
  if (kind_ == BaselineKind::kOpenLoopCounting) {
    remaining_ = std::llround(std::abs(d) / p_.nominal_step_m);
    if (remaining_ > 0) {
      gen_.command(p_.nominal_amplitude_V, p_.frequency_Hz, dir);
      gen_.start(0.0);
      if (remaining_ == 1) gen_.stop_at_period_end();
    }
  } else {
    gen_.command(0.0, p_.frequency_Hz, dir);
    gen_.start(0.0);
  }
  seen_ = gen_.periods();
  active_ = true;
}

void BaselinePositionController::update(double x) noexcept {
  if (!active_ || gen_.periods() == seen_) return;
  const auto done = gen_.periods() - seen_;
  seen_ = gen_.periods();
  const double period = 1.0 / p_.frequency_Hz;
  if (kind_ == BaselineKind::kOpenLoopCounting) {
    remaining_ -= done;
    if (remaining_ <= 1) gen_.stop_at_period_end();  // the period running now is the last one
    return;
  }
  const double e = target_ - x;
  const double sign = e >= 0.0 ? 1.0 : -1.0;
  if (sign != last_sign_) pid_.reset();
  last_sign_ = sign;
  const double amp = std::abs(e) < p_.deadband_m ? 0.0 : pid_.update(std::abs(e), period);
  gen_.command(amp, p_.frequency_Hz, sign > 0.0 ? Direction::kForward : Direction::kBackward);
}

stickslip::DriveSegment BaselinePositionController::next_drive(double dt_s) noexcept {
  return gen_.next(dt_s);
}

}  // namespace mc::motion
