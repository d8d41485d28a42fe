#include "microcobot/vision/visual_servo.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>
#include <Eigen/LU>

#include "microcobot/core/error.h"

namespace mc::vision {

void VisualServoParams::validate() const {
  require(std::isfinite(gain_per_s) && gain_per_s > 0.0 && gain_per_s <= 1e3, "servo.gain_per_s",
          "must be finite, within (0, 1000] 1/s", gain_per_s);
  require(std::isfinite(max_speed_m_s) && max_speed_m_s > 0.0 && max_speed_m_s <= 0.1, "servo.max_speed_m_s",
          "must be finite, within (0, 0.1] m/s", max_speed_m_s);
  require(std::isfinite(deadband_m) && deadband_m >= 0.0 && deadband_m < 1e-3, "servo.deadband_m",
          "must be finite, within [0, 1 mm)", deadband_m);
  require(std::isfinite(converged_m) && converged_m > 0.0 && converged_m < 1e-3, "servo.converged_m",
          "must be finite, within (0, 1 mm)", converged_m);
  require(std::isfinite(max_feature_age_s) && max_feature_age_s > 0.0, "servo.max_feature_age_s",
          "must be finite and > 0", max_feature_age_s);
}

const char* to_string(ServoStatus s) {
  switch (s) {
    case ServoStatus::kMoving:
      return "moving";
    case ServoStatus::kConverged:
      return "converged";
    case ServoStatus::kHoldLost:
      return "hold (target lost)";
    case ServoStatus::kHoldStale:
      return "hold (stale frame)";
    case ServoStatus::kNoTarget:
      return "no target";
  }
  return "?";
}

VisualServo::VisualServo(const VisualServoParams& params, const AffineMap& calibration, int width_px,
                         int height_px)
    : p_(params), A_(calibration.A), width_(width_px), height_(height_px) {
  p_.validate();
  require(width_px >= 1 && height_px >= 1, "servo image size", "must be at least 1 x 1 px",
          std::min(width_px, height_px));
  require(A_.allFinite(), "servo calibration A", "must be finite");
  const double det = A_.determinant();
  // |det A| is (px/m)^2 (~1e12 at 10x): compare with the product of the column norms.
  require(std::abs(det) > 1e-9 * A_.col(0).norm() * A_.col(1).norm(), "servo calibration A",
          "must be invertible (the stage's axes must not appear parallel)", det);
  A_inv_ = A_.inverse();
}

void VisualServo::set_target(double u_px, double v_px) {
  // Continuous pixel coordinates: pixel (i, j) spans [j - 1/2, j + 1/2] (template_tracker.h).
  if (!std::isfinite(u_px) || !std::isfinite(v_px) || u_px < -0.5 || v_px < -0.5 || u_px > width_ - 0.5 ||
      v_px > height_ - 0.5)
    throw InvalidInput(
        fmt::format("servo target ({}, {}) px: not inside the {}x{} frame", u_px, v_px, width_, height_));
  target_ = {u_px, v_px};
  has_target_ = true;
  clear_history();
}

void VisualServo::clear_history() noexcept { head_ = count_ = 0; }

void VisualServo::remember(double t_s, double hold_s, const Eigen::Vector2d& v) noexcept {
  history_[head_] = Segment{t_s, std::isnan(hold_s) ? 0.0 : std::max(hold_s, 0.0), v};
  head_ = (head_ + 1) % kHistory;
  count_ = std::min(count_ + 1, kHistory);
}

Eigen::Vector2d VisualServo::commanded_motion(double t0_s, double t1_s) const noexcept {
  // Walk back from the newest command: each one holds from its start to the next one's.
  Eigen::Vector2d d = Eigen::Vector2d::Zero();
  double end = t1_s;
  for (std::size_t k = 0; k < count_; ++k) {
    const Segment& s = history_[(head_ + kHistory - 1 - k) % kHistory];
    const double begin = std::max(s.t_s, t0_s);
    const double stop = std::min(end, s.t_s + s.hold_s);
    if (stop > begin) d += s.v * (stop - begin);
    end = std::min(end, s.t_s);
    if (end <= t0_s) break;
  }
  return d;
}

ServoCommand VisualServo::step(const ServoFeature& f, double t_now_s, double hold_s) noexcept {
  ServoCommand c;
  if (!has_target_) {
    remember(t_now_s, hold_s, c.velocity_m_s);
    return c;
  }
  const bool finite = std::isfinite(f.u_px) && std::isfinite(f.v_px) && std::isfinite(f.t_mid_exposure_s) &&
                      std::isfinite(t_now_s);
  if (!f.found || !finite) {
    c.status = ServoStatus::kHoldLost;
  } else if (t_now_s - f.t_mid_exposure_s > p_.max_feature_age_s || f.t_mid_exposure_s > t_now_s) {
    c.status = ServoStatus::kHoldStale;
  }
  if (c.status == ServoStatus::kHoldLost || c.status == ServoStatus::kHoldStale) {
    remember(t_now_s, hold_s, c.velocity_m_s);  // zero: the stage holds
    return c;
  }
  // e(t_now) = e(t_m) + A_hat * (stage motion commanded since t_m).
  const Eigen::Vector2d seen = Eigen::Vector2d(f.u_px, f.v_px) - target_;
  c.error_px = seen + A_ * commanded_motion(f.t_mid_exposure_s, t_now_s);
  c.error_m = A_inv_ * c.error_px;
  const double err = c.error_m.norm();
  c.status = err <= p_.converged_m ? ServoStatus::kConverged : ServoStatus::kMoving;
  if (err > p_.deadband_m) {
    c.velocity_m_s = -p_.gain_per_s * c.error_m;  // v = -lambda L^+ e
    const double speed = c.velocity_m_s.norm();
    if (speed > p_.max_speed_m_s) c.velocity_m_s *= p_.max_speed_m_s / speed;
  }
  remember(t_now_s, hold_s, c.velocity_m_s);
  return c;
}

}  // namespace mc::vision
