#include "microcobot/motion/pose_trajectory.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <Eigen/Geometry>

#include "microcobot/core/error.h"

namespace mc::motion {
namespace {

bool finite(const PlatformTransform& T) { return T.R.allFinite() && T.d.allFinite(); }

}  // namespace

void PoseMoveLimits::validate() const {
  require(std::isfinite(max_speed_m_s) && max_speed_m_s > 0.0, "max_speed_m_s", "must be > 0", max_speed_m_s);
  require(std::isfinite(max_angular_speed_rad_s) && max_angular_speed_rad_s > 0.0, "max_angular_speed_rad_s",
          "must be > 0", max_angular_speed_rad_s);
  require(std::isfinite(max_acceleration_m_s2) && max_acceleration_m_s2 > 0.0, "max_acceleration_m_s2",
          "must be > 0", max_acceleration_m_s2);
  require(std::isfinite(max_angular_acceleration_rad_s2) && max_angular_acceleration_rad_s2 > 0.0,
          "max_angular_acceleration_rad_s2", "must be > 0", max_angular_acceleration_rad_s2);
  require(std::isfinite(max_leg_speed_m_s) && max_leg_speed_m_s > 0.0, "max_leg_speed_m_s", "must be > 0",
          max_leg_speed_m_s);
  require(std::isfinite(sample_length_m) && sample_length_m > 0.0, "sample_length_m", "must be > 0",
          sample_length_m);
  require(std::isfinite(sample_angle_rad) && sample_angle_rad > 0.0, "sample_angle_rad", "must be > 0",
          sample_angle_rad);
  require(min_samples >= 2, "min_samples", "must be >= 2", min_samples);
  require(std::isfinite(tool_x_m) && std::abs(tool_x_m) < 1.0, "tool_x_m", "must be finite and < 1 m",
          tool_x_m);
  require(std::isfinite(tool_y_m) && std::abs(tool_y_m) < 1.0, "tool_y_m", "must be finite and < 1 m",
          tool_y_m);
  require(std::isfinite(tool_z_m) && std::abs(tool_z_m) < 1.0, "tool_z_m", "must be finite and < 1 m",
          tool_z_m);
}

PoseTrajectory::PoseTrajectory(const PlatformTransform& start, const PlatformTransform& goal,
                               const PoseMoveLimits& limits)
    : lim_(limits), start_(start), goal_(goal) {
  lim_.validate();
  if (!finite(start) || !finite(goal)) throw InvalidInput("a pose of the move is not finite");
  c_ = lim_.tool_m();
  xc0_ = start.R * c_ + start.d;
  dx_ = goal.R * c_ + goal.d - xc0_;
  omega_ = log_so3(start.R.transpose() * goal.R);
  length_ = dx_.norm();
  angle_ = omega_.norm();
  // The limits on s', s'' from each half of the motion (a half that does not move sets none).
  double v = HUGE_VAL, a = HUGE_VAL;
  if (length_ > 0.0) {
    v = std::min(v, lim_.max_speed_m_s / length_);
    a = std::min(a, lim_.max_acceleration_m_s2 / length_);
  }
  if (angle_ > 0.0) {
    v = std::min(v, lim_.max_angular_speed_rad_s / angle_);
    a = std::min(a, lim_.max_angular_acceleration_rad_s2 / angle_);
  }
  if (!(length_ > 0.0 || angle_ > 0.0)) return;  // no motion: duration 0
  s_ddot_max_ = a;
  if (v * v / a >= 1.0) {  // triangle: accelerate over s = 1/2, decelerate over the rest
    s_dot_max_ = std::sqrt(a);
    t_acc_ = s_dot_max_ / a;
    t_cruise_ = 0.0;
  } else {
    s_dot_max_ = v;
    t_acc_ = v / a;
    t_cruise_ = (1.0 - v * v / a) / v;
  }
  duration_ = 2.0 * t_acc_ + t_cruise_;
}

Eigen::Vector3d PoseTrajectory::tool_point(double s) const noexcept {
  return xc0_ + std::clamp(s, 0.0, 1.0) * dx_;
}

PlatformTransform PoseTrajectory::at(double s) const noexcept {
  s = std::clamp(s, 0.0, 1.0);
  PlatformTransform T;
  T.R = start_.R * exp_so3(s * omega_);
  T.d = xc0_ + s * dx_ - T.R * c_;
  return T;
}

void PoseTrajectory::profile(double t, double& s, double& s_dot, double& s_ddot) const noexcept {
  if (duration_ <= 0.0 || t >= duration_) {
    s = 1.0, s_dot = 0.0, s_ddot = 0.0;
    return;
  }
  if (t <= 0.0) {
    s = 0.0, s_dot = 0.0, s_ddot = 0.0;
    return;
  }
  const double a = s_ddot_max_, v = s_dot_max_;
  const double s_acc = 0.5 * a * t_acc_ * t_acc_;
  if (t < t_acc_) {
    s = 0.5 * a * t * t, s_dot = a * t, s_ddot = a;
  } else if (t < t_acc_ + t_cruise_) {
    s = s_acc + v * (t - t_acc_), s_dot = v, s_ddot = 0.0;
  } else {
    const double r = duration_ - t;  // time left
    s = 1.0 - 0.5 * a * r * r, s_dot = a * r, s_ddot = -a;
  }
}

bool PoseTrajectory::legs_at(const ParallelKinematics& k, double t_s, LegReference& out) const noexcept {
  double s = 0.0, sd = 0.0, sdd = 0.0;
  profile(t_s, s, sd, sdd);
  if (!k.inverse(at(s), out.q)) return false;
  if (sd == 0.0 && sdd == 0.0) {
    out.v.setZero();
    out.a.setZero();
    return true;
  }
  // Central differences over s (one-sided by the same h at the ends: at() clamps s).
  constexpr double h = 1e-4;
  const double s_lo = std::max(0.0, s - h), s_hi = std::min(1.0, s + h);
  const double s_mid = 0.5 * (s_lo + s_hi), hh = 0.5 * (s_hi - s_lo);
  LegCoordinates q_lo, q_hi, q_mid;
  if (!k.inverse(at(s_lo), q_lo) || !k.inverse(at(s_hi), q_hi) || !k.inverse(at(s_mid), q_mid)) return false;
  const LegCoordinates q_s = (q_hi - q_lo) / (2.0 * hh);
  const LegCoordinates q_ss = (q_hi - 2.0 * q_mid + q_lo) / (hh * hh);
  out.v = q_s * sd;
  out.a = q_ss * (sd * sd) + q_s * sdd;
  return true;
}

PathDeviation PoseTrajectory::deviation(const PlatformTransform& T) const noexcept {
  PathDeviation dev;
  const Eigen::Vector3d x = T.R * c_ + T.d;
  const double s_pos = length_ > 0.0 ? std::clamp((x - xc0_).dot(dx_) / (length_ * length_), 0.0, 1.0) : 0.0;
  dev.position_m = (x - tool_point(s_pos)).norm();
  const Eigen::Vector3d w = log_so3(start_.R.transpose() * T.R);
  const double s_rot = angle_ > 0.0 ? std::clamp(w.dot(omega_) / (angle_ * angle_), 0.0, 1.0) : 0.0;
  dev.rotation_rad = log_so3(exp_so3(s_rot * omega_).transpose() * start_.R.transpose() * T.R).norm();
  return dev;
}

MoveCheck check_move(const ParallelKinematics& k, const PoseTrajectory& traj) {
  const auto& lim = traj.limits();
  const int n = std::max({lim.min_samples, static_cast<int>(std::ceil(traj.length_m() / lim.sample_length_m)),
                          static_cast<int>(std::ceil(traj.angle_rad() / lim.sample_angle_rad))});
  MoveCheck out;
  auto refuse = [&](const std::string& where, const PlatformTransform& T, const ReachCheck& c) {
    out.ok = false;
    out.reach = c.reach;
    out.reason = where + PoseUnreachable(to_smarpod(T), c).what();
  };
  const ReachCheck c0 = check_pose(k, traj.start());
  ++out.samples;
  if (!c0.ok()) {
    refuse("start: ", traj.start(), c0);
    return out;
  }
  const ReachCheck c1 = check_pose(k, traj.goal());
  ++out.samples;
  if (!c1.ok()) {
    refuse("goal: ", traj.goal(), c1);
    return out;
  }
  LegCoordinates prev = c0.q;
  double max_dq_ds = 0.0;
  for (int i = 1; i <= n; ++i) {
    const double s = static_cast<double>(i) / n;
    LegCoordinates q = c1.q;
    if (i < n) {
      const PlatformTransform T = traj.at(s);
      const ReachCheck c = check_pose(k, T);
      ++out.samples;
      if (!c.ok()) {
        refuse(fmt::format("along the line at s = {:.4f}: ", s), T, c);
        return out;
      }
      q = c.q;
    }
    max_dq_ds = std::max(max_dq_ds, (q - prev).cwiseAbs().maxCoeff() * n);
    prev = q;
  }
  out.peak_leg_speed_m_s = max_dq_ds * traj.peak_s_dot();
  if (out.peak_leg_speed_m_s > lim.max_leg_speed_m_s) {
    out.ok = false;
    out.reach = Reach::kReachable;
    out.reason = fmt::format(
        "a leg would move at {:.3g} mm/s, beyond max_leg_speed_m_s = {:.3g} mm/s: lower the speed",
        out.peak_leg_speed_m_s * 1e3, lim.max_leg_speed_m_s * 1e3);
  }
  return out;
}

}  // namespace mc::motion
