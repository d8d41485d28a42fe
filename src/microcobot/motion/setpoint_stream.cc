#include "microcobot/motion/setpoint_stream.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::motion {

void SetpointStreamParams::validate() const {
  require_non_negative(delay_s, "stream.delay_s");
  require(capacity >= 2 && capacity <= 100000, "stream.capacity", "must be in [2, 100000]", capacity);
  require_positive(max_velocity_m_s, "stream.max_velocity_m_s");
}

SetpointStream::SetpointStream(const SetpointStreamParams& p, double x0_m)
    : p_((p.validate(), p)), ring_(static_cast<std::size_t>(p.capacity)) {
  out_.x_m = x0_m;
}

void SetpointStream::reset(double x0_m) noexcept {
  head_ = count_ = 0;
  out_ = ReferenceSample{x0_m, 0.0, 0.0};
  holding_ = false;
}

bool SetpointStream::push(double stamp_s, double x_m) noexcept {
  if (!std::isfinite(stamp_s) || !std::isfinite(x_m)) return false;
  if (count_ > 0 && stamp_s <= at(count_ - 1).t) return false;
  if (count_ == ring_.size()) {  // full: drop the oldest
    head_ = (head_ + 1) % ring_.size();
    --count_;
  }
  ring_[(head_ + count_) % ring_.size()] = Entry{stamp_s, x_m};
  ++count_;
  return true;
}

ReferenceSample SetpointStream::sample(double t_s, double dt_s) noexcept {
  if (count_ == 0) {
    holding_ = true;
    return follow(out_.x_m, dt_s);
  }
  const double tq = t_s - p_.delay_s;
  // Drop setpoints that the interpolation has passed (keep one before tq).
  while (count_ >= 2 && at(1).t <= tq) {
    head_ = (head_ + 1) % ring_.size();
    --count_;
  }
  double x = at(0).x;
  holding_ = false;
  if (tq <= at(0).t) {
    x = at(0).x;
  } else if (count_ >= 2) {
    const Entry& a = at(0);
    const Entry& b = at(1);
    x = a.x + (b.x - a.x) * (tq - a.t) / (b.t - a.t);
  } else {
    holding_ = true;  // past the newest setpoint: hold it, never extrapolate
  }
  return follow(x, dt_s);
}

ReferenceSample SetpointStream::follow(double x_m, double dt_s) noexcept {
  const double step = p_.max_velocity_m_s * dt_s;
  const double x_new = out_.x_m + std::clamp(x_m - out_.x_m, -step, step);
  const double v_new = dt_s > 0.0 ? (x_new - out_.x_m) / dt_s : 0.0;
  out_ = ReferenceSample{x_new, v_new, dt_s > 0.0 ? (v_new - out_.v_m_s) / dt_s : 0.0};
  return out_;
}

}  // namespace mc::motion
