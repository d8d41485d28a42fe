#include "microcobot/motion/path_generator.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "microcobot/core/error.h"

namespace mc::motion {

void PathLimits::validate() const {
  require_positive(max_velocity_m_s, "path.max_velocity_m_s");
  require_positive(max_acceleration_m_s2, "path.max_acceleration_m_s2");
  require_positive(max_jerk_m_s3, "path.max_jerk_m_s3");
}

PathGenerator PathGenerator::line(const Eigen::Vector3d& from_m, const Eigen::Vector3d& to_m,
                                  const PathLimits& lim, double sample_s) {
  lim.validate();
  require(from_m.allFinite() && to_m.allFinite(), "path.line", "end points must be finite");
  PathGenerator g;
  g.p0_ = from_m;
  g.length_ = (to_m - from_m).norm();
  g.dir_ = g.length_ > 0.0 ? Eigen::Vector3d((to_m - from_m) / g.length_) : Eigen::Vector3d::UnitX();
  g.v_path_ = lim.max_velocity_m_s;
  g.build_profile(lim, sample_s);
  return g;
}

PathGenerator PathGenerator::arc(const Eigen::Vector3d& from_m, const Eigen::Vector3d& center_m,
                                 const Eigen::Vector3d& axis, double angle_rad, const PathLimits& lim,
                                 double sample_s) {
  lim.validate();
  require(from_m.allFinite() && center_m.allFinite() && axis.allFinite() && axis.norm() > 0.0, "path.arc",
          "points and axis must be finite, axis non-zero");
  require(std::isfinite(angle_rad) && std::abs(angle_rad) <= 2.0 * std::numbers::pi, "path.arc.angle_rad",
          "must be finite and |angle| <= 2 pi", angle_rad);
  PathGenerator g;
  g.is_arc_ = true;
  const Eigen::Vector3d n = axis.normalized();
  const Eigen::Vector3d rel = from_m - center_m;
  const Eigen::Vector3d perp = rel - n * n.dot(rel);
  g.radius_ = perp.norm();
  require(g.radius_ > 0.0, "path.arc", "the start point must not lie on the axis");
  g.c_ = center_m + n * n.dot(rel);  // the circle's centre in the start point's plane
  g.u_ = perp / g.radius_;
  g.w_ = n.cross(g.u_);
  g.angle_ = angle_rad;
  g.p0_ = from_m;
  g.length_ = g.radius_ * std::abs(angle_rad);
  // Centripetal acceleration v^2 / R within half the acceleration budget.
  g.v_path_ = std::min(lim.max_velocity_m_s, std::sqrt(0.5 * lim.max_acceleration_m_s2 * g.radius_));
  g.build_profile(lim, sample_s);
  return g;
}

void PathGenerator::build_profile(const PathLimits& lim, double sample_s) {
  require_positive(sample_s, "path.sample_s");
  h_ = sample_s;
  const double a = is_arc_ ? 0.5 * lim.max_acceleration_m_s2 : lim.max_acceleration_m_s2;
  const double v = v_path_, len = length_;
  // Trapezoid (or triangle) on s.
  double t_acc = v / a, t_cruise = 0.0, v_peak = v;
  if (len < v * v / a) {
    v_peak = std::sqrt(len * a);
    t_acc = v_peak / a;
  } else {
    t_cruise = (len - v * v / a) / v;
  }
  const double t_trap = 2.0 * t_acc + t_cruise;
  auto s_trap = [&](double t) {
    if (t <= 0.0) return 0.0;
    if (t < t_acc) return 0.5 * a * t * t;
    if (t < t_acc + t_cruise) return 0.5 * a * t_acc * t_acc + v_peak * (t - t_acc);
    if (t < t_trap) {
      const double r = t_trap - t;
      return len - 0.5 * a * r * r;
    }
    return len;
  };
  // Moving average of length T_j = 2 a / j: an acceleration step becomes a ramp of slope <= j,
  // a reversal (+a to -a) too.
  const double tj = 2.0 * a / lim.max_jerk_m_s3;
  const auto m = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(tj / h_)));
  duration_ = t_trap + static_cast<double>(m) * h_;
  const auto n = static_cast<std::size_t>(std::ceil(duration_ / h_)) + 2;
  std::vector<double> raw(n + m);
  for (std::size_t k = 0; k < raw.size(); ++k) {
    raw[k] = s_trap((static_cast<double>(k) - static_cast<double>(m)) * h_);
  }
  s_.assign(n, 0.0);
  double acc = 0.0;
  for (std::size_t k = 0; k < m; ++k) acc += raw[k + 1];
  for (std::size_t k = 0; k < n; ++k) {
    s_[k] = acc / static_cast<double>(m);
    if (k + m + 1 < raw.size()) acc += raw[k + m + 1] - raw[k + 1];
  }
  s_.front() = 0.0;
  v_.assign(n, 0.0);
  a_.assign(n, 0.0);
  for (std::size_t k = 1; k + 1 < n; ++k) {
    v_[k] = (s_[k + 1] - s_[k - 1]) / (2.0 * h_);
    a_[k] = (s_[k + 1] - 2.0 * s_[k] + s_[k - 1]) / (h_ * h_);
  }
}

Eigen::Vector3d PathGenerator::point_at(double s) const noexcept {
  s = std::clamp(s, 0.0, length_);
  if (!is_arc_) return p0_ + dir_ * s;
  const double phi = std::copysign(s / radius_, angle_);
  return c_ + radius_ * (std::cos(phi) * u_ + std::sin(phi) * w_);
}

Eigen::Vector3d PathGenerator::tangent_at(double s) const noexcept {
  if (!is_arc_) return dir_;
  const double sg = angle_ >= 0.0 ? 1.0 : -1.0;
  const double phi = sg * std::clamp(s, 0.0, length_) / radius_;
  return sg * (-std::sin(phi) * u_ + std::cos(phi) * w_);
}

Eigen::Vector3d PathGenerator::curvature_at(double s) const noexcept {
  if (!is_arc_) return Eigen::Vector3d::Zero();
  const double phi = std::copysign(std::clamp(s, 0.0, length_) / radius_, angle_);
  return -(std::cos(phi) * u_ + std::sin(phi) * w_) / radius_;
}

PathSample PathGenerator::sample(double t) const noexcept {
  PathSample out;
  const double pos = std::clamp(t / h_, 0.0, static_cast<double>(s_.size() - 1));
  const auto k = std::min(static_cast<std::size_t>(pos), s_.size() - 2);
  const double f = pos - static_cast<double>(k);
  const double s = s_[k] + f * (s_[k + 1] - s_[k]);
  const double v = v_[k] + f * (v_[k + 1] - v_[k]);
  const double a = a_[k] + f * (a_[k + 1] - a_[k]);
  out.s_m = s;
  out.x_m = point_at(s);
  out.v_m_s = tangent_at(s) * v;
  out.a_m_s2 = tangent_at(s) * a + curvature_at(s) * v * v;
  return out;
}

double PathGenerator::distance_to_path(const Eigen::Vector3d& p) const noexcept {
  if (!is_arc_) {
    const double s = std::clamp((p - p0_).dot(dir_), 0.0, length_);
    return (p - point_at(s)).norm();
  }
  const Eigen::Vector3d n = u_.cross(w_);
  const Eigen::Vector3d rel = p - c_;
  const double h = n.dot(rel);
  const Eigen::Vector3d plane = rel - h * n;
  double phi = std::atan2(plane.dot(w_), plane.dot(u_));  // (-pi, pi]
  const double span = std::abs(angle_);
  double along = angle_ >= 0.0 ? phi : -phi;  // angle in the arc's sense
  if (along < 0.0) along += 2.0 * std::numbers::pi;
  if (along <= span) return std::hypot(h, plane.norm() - radius_);
  return std::min((p - point_at(0.0)).norm(), (p - point_at(length_)).norm());
}

}  // namespace mc::motion
