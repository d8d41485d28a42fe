#include "microcobot/haptics/pantograph.h"

#include <cmath>
#include <numbers>

#include "microcobot/core/error.h"

namespace mc::haptics {

void PantographParams::validate() const {
  require_positive(base_separation_m, "base_separation_m");
  require_positive(proximal_m, "proximal_m");
  require_positive(distal_m, "distal_m");
  require(theta_max_rad > theta_min_rad, "theta_max_rad", "must exceed theta_min_rad", theta_max_rad);
  require_in_range(min_transmission_rad, 0.0, 1.5, "min_transmission_rad");
  require(proximal_m + distal_m > 0.5 * base_separation_m, "distal_m", "links too short to close the loop",
          distal_m);
}

Pantograph::Pantograph(const PantographParams& params) : params_(params) { params_.validate(); }

Eigen::Vector2d Pantograph::base(int i) const {
  return {i == 0 ? -0.5 * params_.base_separation_m : 0.5 * params_.base_separation_m, 0.0};
}

Eigen::Vector2d Pantograph::elbow(int i, double theta) const {
  return base(i) + params_.proximal_m * Eigen::Vector2d(std::cos(theta), std::sin(theta));
}

bool Pantograph::forward(const Eigen::Vector2d& q, Eigen::Vector2d& x) const {
  const Eigen::Vector2d p1 = elbow(0, q(0));
  const Eigen::Vector2d p2 = elbow(1, q(1));
  const Eigen::Vector2d d = p2 - p1;
  const double dist = d.norm();
  const double l = params_.distal_m;
  if (dist < 1e-12 || dist >= 2.0 * l) return false;
  const double h = std::sqrt(l * l - 0.25 * dist * dist);
  const Eigen::Vector2d mid = 0.5 * (p1 + p2);
  // Perpendicular to p1->p2 rotated +90 deg: with the left elbow at p1 this points away
  // from the base for the working ("elbows out") configuration.
  const Eigen::Vector2d n(-d(1) / dist, d(0) / dist);
  x = mid + h * n;
  return true;
}

bool Pantograph::inverse(const Eigen::Vector2d& x, Eigen::Vector2d& q) const {
  const double lp = params_.proximal_m;
  const double ld = params_.distal_m;
  for (int i = 0; i < 2; ++i) {
    const Eigen::Vector2d r = x - base(i);
    const double dist = r.norm();
    if (dist >= lp + ld || dist <= std::abs(lp - ld)) return false;
    const double phi = std::atan2(r(1), r(0));
    const double alpha = std::acos((lp * lp + dist * dist - ld * ld) / (2.0 * lp * dist));
    // Left elbow outward (to the left: +alpha), right elbow outward (-alpha).
    q(i) = i == 0 ? phi + alpha : phi - alpha;
  }
  return true;
}

bool Pantograph::jacobian(const Eigen::Vector2d& q, Eigen::Matrix2d& j) const {
  Eigen::Vector2d x;
  if (!forward(q, x)) return false;
  // Loop closure |x - p_i(theta_i)|^2 = l_d^2  =>  (x - p_i)^T dx = (x - p_i)^T p_i' dtheta_i.
  Eigen::Matrix2d a;
  Eigen::Matrix2d b = Eigen::Matrix2d::Zero();
  for (int i = 0; i < 2; ++i) {
    const Eigen::Vector2d r = x - elbow(i, q(i));
    const Eigen::Vector2d dp = params_.proximal_m * Eigen::Vector2d(-std::sin(q(i)), std::cos(q(i)));
    a.row(i) = r.transpose();
    b(i, i) = r.dot(dp);
  }
  const double det = a.determinant();
  if (std::abs(det) < 1e-9 * params_.distal_m * params_.distal_m) return false;
  j = a.inverse() * b;
  return true;
}

bool Pantograph::torques(const Eigen::Vector2d& q, const Eigen::Vector2d& f, Eigen::Vector2d& tau) const {
  Eigen::Matrix2d j;
  if (!jacobian(q, j)) return false;
  tau = j.transpose() * f;
  return true;
}

bool Pantograph::in_workspace(const Eigen::Vector2d& x) const {
  Eigen::Vector2d q;
  if (!inverse(x, q)) return false;
  for (int i = 0; i < 2; ++i) {
    if (q(i) < params_.theta_min_rad || q(i) > params_.theta_max_rad) return false;
  }
  // Angle between the two distal links at the handle: 0 or pi means a singular pose.
  const Eigen::Vector2d u1 = (elbow(0, q(0)) - x).normalized();
  const Eigen::Vector2d u2 = (elbow(1, q(1)) - x).normalized();
  const double angle = std::acos(std::clamp(u1.dot(u2), -1.0, 1.0));
  const double m = params_.min_transmission_rad;
  return angle > m && angle < std::numbers::pi - m;
}

Eigen::Vector2d Pantograph::workspace_centre() const {
  const double reach = params_.proximal_m + params_.distal_m;
  return {0.0, 0.6 * reach};
}

}  // namespace mc::haptics
