#include "microcobot/motion/position_controller.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::motion {

using stickslip::Direction;

void PositionControlParams::validate() const {
  require_positive(control_rate_Hz, "position.control_rate_Hz");
  require_positive(step_frequency_Hz, "position.step_frequency_Hz");
  require_positive(max_velocity_m_s, "position.max_velocity_m_s");
  require_non_negative(approach_distance_m, "position.approach_distance_m");
  require_positive(approach_frequency_Hz, "position.approach_frequency_Hz");
  require(step_fraction > 0.0 && step_fraction <= 1.0, "position.step_fraction", "must be in (0, 1]",
          step_fraction);
  require_positive(scan_velocity_m_s, "position.scan_velocity_m_s");
  require_positive(scan_acceleration_m_s2, "position.scan_acceleration_m_s2");
  require_positive(scan_ki_1_s, "position.scan_ki_1_s");
  require_positive(hold_ki_1_s, "position.hold_ki_1_s");
  require(reach_margin > 0.0 && reach_margin <= 1.0, "position.reach_margin", "must be in (0, 1]",
          reach_margin);
  require_non_negative(backward_window_m, "position.backward_window_m");
  require_in_range(raise_voltage_V, 1.0, 100.0, "position.raise_voltage_V");
  require_non_negative(stroke_margin_m, "position.stroke_margin_m");
  require_positive(in_position_m, "position.in_position_m");
  require_non_negative(settle_s, "position.settle_s");
  require_positive(filter_s, "position.filter_s");
  require(saturation_ticks >= 1, "position.saturation_ticks", "must be >= 1", saturation_ticks);
  require_in_range(stall_fraction, 0.0, 1.0, "position.stall_fraction");
  require(stall_periods >= 1, "position.stall_periods", "must be >= 1", stall_periods);
}

std::string to_string(AxisMode m) {
  switch (m) {
    case AxisMode::kIdle:
      return "idle";
    case AxisMode::kStepping:
      return "stepping";
    case AxisMode::kRaise:
      return "raise";
    case AxisMode::kScanning:
      return "scanning";
    case AxisMode::kHold:
      return "hold";
    case AxisMode::kEndStop:
      return "end-stop";
    case AxisMode::kEmergencyStop:
      return "emergency-stop";
  }
  return "idle";
}

PositionController::PositionController(const PositionControlParams& p,
                                       const stickslip::StickSlipParams& model, const StepMap& map)
    : p_(p),
      map_(map),
      pi_(model.hysteresis),
      obs_(stickslip::make_pi_state(model.hysteresis, 0.0)),
      g_(model.pe.static_gain_m_V),
      u_min_(model.drive.min_V),
      u_max_(model.drive.max_V),
      slew_(model.drive.slew_rate_V_s),
      gen_(model.drive.slew_rate_V_s),
      scan_ref_(MotionLimits{p.scan_velocity_m_s, p.scan_acceleration_m_s2}),
      dt_c_(1.0 / p.control_rate_Hz) {
  p_.validate();
  model.validate();
}

double PositionController::pe_displacement_m(double u_V) const noexcept {
  return g_ * stickslip::pi_peek(pi_, obs_, u_V);
}

double PositionController::inverse_V(double y_m) const noexcept {
  return stickslip::pi_peek_inverse(pi_, obs_, y_m / g_, u_min_, u_max_);
}

void PositionController::set_target(double target_m, double velocity_m_s) noexcept {
  target_ = target_m;
  v_ff_ = velocity_m_s;
  has_target_ = true;
  raise_count_ = 0;
  raise_stalls_ = 0;
  if (mode_ == AxisMode::kEndStop || mode_ == AxisMode::kEmergencyStop || mode_ == AxisMode::kIdle) {
    gen_.halt();
    mode_ = AxisMode::kIdle;  // decide() at the next update
  } else if (mode_ == AxisMode::kHold) {
    mode_ = AxisMode::kScanning;
    settled_s_ = 0.0;
  }
}

void PositionController::emergency_stop() noexcept {
  gen_.halt();
  u_ = 0.0;
  u_cmd_ = 0.0;
  mode_ = AxisMode::kEmergencyStop;
}

void PositionController::enter_scan(double x) noexcept {
  if (mode_ == AxisMode::kStepping || mode_ == AxisMode::kRaise) ++switches_;
  mode_ = AxisMode::kScanning;
  x_entry_ = x;
  y_entry_ = pe_displacement_m(u_);
  ref_ = x;
  scan_ref_.reset(x);
  integ_ = 0.0;
  u_cmd_ = u_;
  u_rate_ = 0.0;
  sat_count_ = 0;
  settled_s_ = 0.0;
}

void PositionController::plan_period(double x) noexcept {
  // The period now running was latched earlier: plan the next one from its predicted end.
  const Direction cur = gen_.direction();
  const double cur_step =
      gen_.amplitude_V() > 0.0 ? map_.step_m(gen_.amplitude_V(), gen_.frequency_Hz(), cur) : 0.0;
  const double x_pred = x + (cur == Direction::kForward ? cur_step : -cur_step);
  const double e = target_ - x_pred;
  const double f0 = frequency_for(std::abs(e));
  const Direction dir = e > 0.0 ? Direction::kForward : Direction::kBackward;
  const double d = std::abs(e);
  if (dir == Direction::kForward) {
    // Stop when scanning (from U = 0 V at the period end) can take over.
    const double reach_up =
        p_.reach_margin * g_ *
        (stickslip::pi_loading_curve(pi_, u_max_) - stickslip::pi_loading_curve(pi_, u_min_));
    if (d <= reach_up) {
      gen_.stop_at_period_end();
      return;
    }
  } else if (d <= p_.backward_window_m) {
    gen_.stop_at_period_end();
    return;
  }
  // The largest amplitude whose excursion within the period stays short of the target.
  const double a_min = map_.min_stepping_amplitude_V(f0, dir);
  const double a_reach = map_.amplitude_for_reach(d - p_.stroke_margin_m, f0, dir);
  if (a_reach < a_min) {
    gen_.stop_at_period_end();  // no safe step: scanning (forward) or raise + scan (backward)
    return;
  }
  const double want = std::max(p_.step_fraction * d, std::abs(v_ff_) / f0);
  const double amp = std::clamp(map_.amplitude_for_step(want, f0, dir), a_min, a_reach);
  double f = f0;
  const double s = map_.step_m(amp, f0, dir);
  if (s * f0 > p_.max_velocity_m_s && s > 0.0) f = p_.max_velocity_m_s / s;
  gen_.command(amp, f, dir);
}

void PositionController::decide(double x) noexcept {
  const double e = target_ - x;
  const double up = p_.reach_margin * (pe_displacement_m(u_max_) - pe_displacement_m(u_));
  const double down = p_.reach_margin * (pe_displacement_m(u_) - pe_displacement_m(u_min_));
  if ((e >= 0.0 && e <= up) || (e < 0.0 && -e <= down)) {
    enter_scan(x);
    return;
  }
  const Direction dir = e > 0.0 ? Direction::kForward : Direction::kBackward;
  const double d = std::abs(e);
  const double f0 = frequency_for(d);
  const double a_min = map_.min_stepping_amplitude_V(f0, dir);
  // A period starting at U = u_ adds the PE's present extension to the excursion.
  const double pre = dir == Direction::kForward ? 0.0 : pe_displacement_m(u_) - pe_displacement_m(u_min_);
  const double a_reach = map_.amplitude_for_reach(d - p_.stroke_margin_m - std::max(0.0, pre), f0, dir);
  if (dir == Direction::kBackward && u_ < p_.raise_voltage_V &&
      (d <= p_.backward_window_m || a_reach < a_min)) {
    // Backward finish: raise U with the abrupt edge (the slider mostly stays), then scan down.
    // A raise + a full scan down is a closed-loop backward step, repeated until in reach.
    // Raise cycles that make no progress: the backward end stop.
    const double least = p_.stall_fraction * map_.step_m(p_.raise_voltage_V, p_.approach_frequency_Hz, dir);
    raise_stalls_ = (raise_count_ > 0 && x > x_raise_ - least) ? raise_stalls_ + 1 : 0;
    ++raise_count_;
    x_raise_ = x;
    if (raise_stalls_ >= 3) {
      u_ = 0.0;
      mode_ = AxisMode::kEndStop;
      return;
    }
    mode_ = AxisMode::kRaise;
    return;
  }
  const double want = std::max(p_.step_fraction * d, std::abs(v_ff_) / f0);
  // Forward with no safe amplitude and out of scanning reach: the smallest stepping amplitude.
  const double amp = std::max(a_min, std::min(map_.amplitude_for_step(want, f0, dir), a_reach));
  double f = f0;
  const double s = map_.step_m(amp, f0, dir);
  if (s * f0 > p_.max_velocity_m_s && s > 0.0) f = p_.max_velocity_m_s / s;
  gen_.command(amp, f, dir);
  gen_.start(u_);
  mode_ = AxisMode::kStepping;
  seen_periods_ = gen_.periods();
  x_period_ = x;
  x_window_ = x;
  expected_step_ = s;
  expected_sum_ = 0.0;
  stall_count_ = 0;
}

void PositionController::update(double x) noexcept {
  if (!have_x_) {
    x_filt_ = x;
    have_x_ = true;
  }
  x_filt_ += dt_c_ / (p_.filter_s + dt_c_) * (x - x_filt_);
  x_last_ = x;
  switch (mode_) {
    case AxisMode::kEndStop:
    case AxisMode::kEmergencyStop:
      return;
    case AxisMode::kIdle:
      if (has_target_) decide(x);
      return;
    case AxisMode::kStepping: {
      if (gen_.periods() != seen_periods_) {
        seen_periods_ = gen_.periods();
        // End stop: over stall_periods periods the axis moved far less than the model predicts
        // (a window, not single periods: the sampling phase within a period adds jitter).
        const double sign = gen_.direction() == Direction::kForward ? 1.0 : -1.0;
        expected_sum_ += expected_step_;
        if (++stall_count_ >= p_.stall_periods) {
          if (sign * (x - x_window_) < p_.stall_fraction * expected_sum_) {
            gen_.halt();
            u_ = 0.0;
            mode_ = AxisMode::kEndStop;
            return;
          }
          stall_count_ = 0;
          expected_sum_ = 0.0;
          x_window_ = x;
        }
        x_period_ = x;
        expected_step_ = map_.step_m(gen_.amplitude_V(), gen_.frequency_Hz(), gen_.direction());
        if (gen_.running()) plan_period(x);
      }
      if (!gen_.running()) decide(x);
      return;
    }
    case AxisMode::kRaise:
      if (u_ >= p_.raise_voltage_V - 1e-9) enter_scan(x);
      return;
    case AxisMode::kScanning:
    case AxisMode::kHold:
      break;
  }
  // Scanning / hold: ramped reference, PI-inverse feedforward, integral correction.
  ref_ = scan_ref_.step(target_, dt_c_).x_m;
  const double e = ref_ - x;
  const double ki = mode_ == AxisMode::kHold ? p_.hold_ki_1_s : p_.scan_ki_1_s;
  const double y_des = y_entry_ + (ref_ - x_entry_) + integ_;
  const double u_new = inverse_V(y_des);
  const bool sat_hi = u_new >= u_max_ - 1e-6 && e > 0.0;
  const bool sat_lo = u_new <= u_min_ + 1e-6 && e < 0.0;
  if (!sat_hi && !sat_lo) integ_ += ki * e * dt_c_;
  u_rate_ = std::abs(u_new - u_) / dt_c_;
  u_cmd_ = u_new;
  const double err = target_ - x_filt_;
  if ((sat_hi || sat_lo) && std::abs(err) > 10.0 * p_.in_position_m) {
    if (++sat_count_ >= p_.saturation_ticks) {
      mode_ = AxisMode::kIdle;  // out of the PE's reach: back to stepping from the present U
      decide(x);
      return;
    }
  } else {
    sat_count_ = 0;
  }
  if (std::abs(err) < p_.in_position_m && ref_ == target_) {
    settled_s_ += dt_c_;
    if (settled_s_ >= p_.settle_s) mode_ = AxisMode::kHold;
  } else if (mode_ == AxisMode::kScanning) {
    settled_s_ = 0.0;
  }
}

stickslip::DriveSegment PositionController::next_drive(double dt_s) noexcept {
  stickslip::DriveSegment seg;
  switch (mode_) {
    case AxisMode::kStepping:
      seg = gen_.next(dt_s);
      u_ = seg.end_V;
      break;
    case AxisMode::kRaise:
      u_ = std::min(u_ + slew_ * dt_s, p_.raise_voltage_V);
      break;
    case AxisMode::kScanning:
    case AxisMode::kHold: {
      const double du = std::max(u_rate_, 1.0) * dt_s;
      u_ += std::clamp(u_cmd_ - u_, -du, du);
      break;
    }
    case AxisMode::kEndStop:
    case AxisMode::kEmergencyStop:
      u_ = 0.0;
      break;
    case AxisMode::kIdle:
      break;
  }
  // The observer's PI follows the path's turning points too (its hysteresis branches there).
  for (int j = 0; j < seg.corners; ++j) {
    auto& c = seg.u_V[static_cast<std::size_t>(j)];
    c = std::clamp(c, u_min_, u_max_);
    stickslip::pi_update(pi_, obs_, c);
  }
  u_ = std::clamp(u_, u_min_, u_max_);
  stickslip::pi_update(pi_, obs_, u_);
  seg.end_V = u_;
  return seg;
}

}  // namespace mc::motion
