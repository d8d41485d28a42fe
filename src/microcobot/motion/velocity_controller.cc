#include "microcobot/motion/velocity_controller.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::motion {

VelocityMode parse_velocity_mode(const std::string& name) {
  if (name == "model") return VelocityMode::kModelBased;
  if (name == "pid") return VelocityMode::kThesisPid;
  if (name == "open-loop") return VelocityMode::kOpenLoop;
  throw UsageError("--mode must be model, pid or open-loop (got '" + name + "')");
}

std::string to_string(VelocityMode m) {
  switch (m) {
    case VelocityMode::kModelBased:
      return "model";
    case VelocityMode::kThesisPid:
      return "pid";
    case VelocityMode::kOpenLoop:
      return "open-loop";
  }
  return "model";
}

void VelocityControlParams::validate() const {
  require_positive(sawtooth_frequency_Hz, "velocity.sawtooth_frequency_Hz");
  require(delay_periods >= 1 && delay_periods <= VelocityController::kMaxDelay, "velocity.delay_periods",
          "must be in [1, 63]", delay_periods);
  require_positive(control_rate_Hz, "velocity.control_rate_Hz");
  pid.validate();
  require_positive(nominal_step_m, "velocity.nominal_step_m");
  require_positive(nominal_amplitude_V, "velocity.nominal_amplitude_V");
  require_in_range(stall_fraction, 0.0, 1.0, "velocity.stall_fraction");
  require(stall_periods >= 1, "velocity.stall_periods", "must be >= 1", stall_periods);
}

VelocityController::VelocityController(const VelocityControlParams& p, VelocityMode mode, const StepMap* map,
                                       double slew_rate_V_s)
    : p_(p), mode_(mode), map_(map), pid_(p.pid), gen_(slew_rate_V_s) {
  p_.validate();
  if (mode_ == VelocityMode::kModelBased && map_ == nullptr) {
    throw InvalidParams("velocity.mode", "the model-based controller needs a step map");
  }
}

void VelocityController::set_reference(double v_m_s) noexcept {
  if ((v_m_s > 0.0) != (v_ref_ > 0.0)) {
    pid_.reset();
    count_ = 0;
  }
  v_ref_ = v_m_s;
  end_stop_ = false;
  stall_count_ = 0;
}

void VelocityController::emergency_stop() noexcept {
  gen_.halt();
  pid_.reset();
  amp_ = 0.0;
  v_ref_ = 0.0;
  started_ = false;
}

void VelocityController::update(double measured_position_m) noexcept {
  last_x_ = measured_position_m;
  have_x_ = true;
  const double f = p_.sawtooth_frequency_Hz;
  const Direction dir = v_ref_ >= 0.0 ? Direction::kForward : Direction::kBackward;
  const double speed = std::abs(v_ref_);
  if (!started_) {
    // First tick: the amplitude of the first period (feedforward only, no estimate yet).
    ring_[0] = measured_position_m;
    count_ = 1;
    seen_periods_ = gen_.periods();
    if (mode_ == VelocityMode::kOpenLoop) {
      amp_ = std::min(100.0, p_.nominal_amplitude_V * speed / (f * p_.nominal_step_m));
    } else if (mode_ == VelocityMode::kModelBased) {
      amp_ = map_->amplitude_for_step(speed / f, f, dir);
    } else {
      amp_ = 0.0;
    }
    gen_.command(amp_, f, dir);
    gen_.start(gen_.output_V());
    started_ = true;
    return;
  }
  if (gen_.periods() == seen_periods_) return;  // the amplitude changes only at period boundaries
  seen_periods_ = gen_.periods();
  // Positions one period apart in a ring: v = (x_k - x_{k-N}) / (N T).
  for (int i = std::min(count_, kMaxDelay); i > 0; --i)
    ring_[static_cast<std::size_t>(i)] = ring_[static_cast<std::size_t>(i - 1)];
  ring_[0] = measured_position_m;
  count_ = std::min(count_ + 1, kMaxDelay + 1);
  const int n = std::min(p_.delay_periods, count_ - 1);
  if (n < 1) return;
  v_est_ = (ring_[0] - ring_[static_cast<std::size_t>(n)]) / (n / f);
  if (end_stop_) return;
  const double sign = dir == Direction::kForward ? 1.0 : -1.0;
  const double along = sign * v_est_;  // velocity along the commanded direction
  const double period = 1.0 / f;
  if (mode_ == VelocityMode::kOpenLoop) {
    amp_ = std::min(100.0, p_.nominal_amplitude_V * speed / (f * p_.nominal_step_m));
  } else {
    const double ff = mode_ == VelocityMode::kModelBased ? map_->amplitude_for_step(speed / f, f, dir) : 0.0;
    const bool stalled_now = along < p_.stall_fraction * speed && amp_ >= p_.pid.out_max - 1e-9;
    amp_ = pid_.update(speed - along, period, ff, end_stop_ || stalled_now);
  }
  // End stop: no motion at full amplitude for stall_periods periods -> stop driving (no wind-up).
  if (speed > 0.0 && along < p_.stall_fraction * speed && amp_ >= 0.99 * p_.pid.out_max) {
    if (++stall_count_ >= p_.stall_periods) {
      end_stop_ = true;
      amp_ = 0.0;
    }
  } else {
    stall_count_ = 0;
  }
  gen_.command(amp_, f, dir);
}

stickslip::DriveSegment VelocityController::next_drive(double dt_s) noexcept {
  if (!gen_.running() && started_ && amp_ > 0.0) gen_.start(gen_.output_V());
  return gen_.next(dt_s);
}

}  // namespace mc::motion
