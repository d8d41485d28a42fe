#include "microcobot/teleop/virtual_fixtures.h"

#include <algorithm>

#include "microcobot/core/error.h"

namespace mc::teleop {

void VirtualFixtureParams::validate() const {
  require_positive(capture_radius_m, "capture_radius_m");
  require(far_gain >= 1.0 && far_gain <= 50.0, "far_gain", "must be within [1, 50]", far_gain);
  require(far_distance_m > capture_radius_m, "far_distance_m", "must be beyond capture_radius_m",
          far_distance_m);
  require_positive(max_speed_m_s, "max_speed_m_s");
  require_non_negative(display_stiffness_N_m, "display_stiffness_N_m");
  require_positive(max_display_N, "max_display_N");
  require(funnel_half_angle_deg > 0.0 && funnel_half_angle_deg < 89.0, "funnel_half_angle_deg",
          "must be within (0, 89) degrees", funnel_half_angle_deg);
  require_positive(funnel_height_m, "funnel_height_m");
  require_positive(level_rate_1_s, "level_rate_1_s");
  require_positive(height_capture_m, "height_capture_m");
  require(std::isfinite(yaw_capture_rad) && yaw_capture_rad > 0.0 && yaw_capture_rad <= 0.5,
          "yaw_capture_rad", "must be within (0, 0.5] rad", yaw_capture_rad);
}

VirtualFixtures::VirtualFixtures(const VirtualFixtureParams& params) : p_(params) {
  p_.validate();
  tan_cone_ = std::tan(p_.funnel_half_angle_deg * M_PI / 180.0);
}

namespace {

bool keep_outs_valid(const FixtureSet& set) noexcept {
  if (set.keep_out_count < 0 || set.keep_out_count > FixtureSet::kMaxKeepOuts) return false;
  for (int i = 0; i < set.keep_out_count; ++i) {
    const auto& k = set.keep_outs[static_cast<std::size_t>(i)];
    if (!k.xy_m.allFinite() || !std::isfinite(k.radius_m) || k.radius_m < 0.0 || !std::isfinite(k.top_z_m))
      return false;
  }
  return true;
}

}  // namespace

void VirtualFixtures::set(const FixtureSet& set) noexcept {
  const bool valid = std::isfinite(set.level) && set.level >= 0.0 && set.level <= 1.0 &&
                     set.guide_xy_m.allFinite() && set.path_from_xy_m.allFinite() &&
                     std::isfinite(set.rim_z_m) && std::isfinite(set.funnel_radius_m) &&
                     set.funnel_radius_m >= 0.0 && std::isfinite(set.height_z_m) &&
                     std::isfinite(set.yaw_rad) && keep_outs_valid(set);
  const FixtureSet next = valid ? set : FixtureSet{};
  if (next == set_) return;
  // A new guide moves the field under the handle: its energy is booked afresh. A new level alone
  // is slewed, and what it would add is the passivity controller's to dissipate.
  if (next.guide != set_.guide || next.guide_xy_m != set_.guide_xy_m || next.path != set_.path ||
      next.path_from_xy_m != set_.path_from_xy_m) {
    rebase_ = true;
    level_ = 0.0;  // from nothing again: the new field comes in at level_rate_1_s
  }
  if (next.height != set_.height || next.height_z_m != set_.height_z_m) height_level_ = 0.0;
  set_ = next;
}

void VirtualFixtures::tick(double dt_s) noexcept {
  const double step = p_.level_rate_1_s * dt_s;
  level_ += std::clamp(set_.level - level_, -step, step);
  const double height_goal = set_.height ? set_.level : 0.0;
  height_level_ += std::clamp(height_goal - height_level_, -step, step);
}

double VirtualFixtures::weight(double d) const noexcept {
  const double r = p_.capture_radius_m;
  return std::clamp((2.0 * r - d) / r, 0.0, 1.0);
}

double VirtualFixtures::potential_J(double d, double a, double s) const noexcept {
  const double r = p_.capture_radius_m;
  double integral;  // int_0^d w(x) x dx
  if (d <= r) {
    integral = 0.5 * d * d;
  } else if (d < 2.0 * r) {
    integral = 0.5 * r * r + d * d - d * d * d / (3.0 * r) - 2.0 * r * r / 3.0;
  } else {
    integral = 7.0 * r * r / 6.0;
  }
  return p_.display_stiffness_N_m * a / (s * s) * integral;
}

double VirtualFixtures::scale_gain(const Eigen::Vector2d& xy) const noexcept {
  if (!set_.guide) return 1.0;
  const double d = (xy - set_.guide_xy_m).norm();
  const double x =
      std::clamp((d - p_.capture_radius_m) / (p_.far_distance_m - p_.capture_radius_m), 0.0, 1.0);
  return 1.0 + level_ * (p_.far_gain - 1.0) * x;
}

Eigen::Vector2d VirtualFixtures::nearest_guide(const Eigen::Vector2d& xy) const noexcept {
  if (!set_.path) return set_.guide_xy_m;
  const Eigen::Vector2d a = set_.path_from_xy_m, ab = set_.guide_xy_m - a;
  const double l2 = ab.squaredNorm();
  const double u = l2 > 0.0 ? std::clamp((xy - a).dot(ab) / l2, 0.0, 1.0) : 1.0;
  return a + u * ab;
}

Eigen::Vector2d VirtualFixtures::guided(const Eigen::Vector2d& raw_xy) const noexcept {
  if (!set_.guide || level_ <= 0.0) return raw_xy;
  const Eigen::Vector2d g = nearest_guide(raw_xy);
  const Eigen::Vector2d e = raw_xy - g;
  return g + (1.0 - level_ * weight(e.norm())) * e;
}

double VirtualFixtures::guided_z(double raw_z) const noexcept {
  if (!set_.height || height_level_ <= 0.0) return raw_z;
  const double e = raw_z - set_.height_z_m, h = p_.height_capture_m;
  const double w = std::clamp((2.0 * h - std::abs(e)) / h, 0.0, 1.0);
  return set_.height_z_m + (1.0 - height_level_ * w) * e;
}

Eigen::Vector2d VirtualFixtures::confined_xy(const Eigen::Vector2d& xy, double z) const noexcept {
  if (!set_.guide || !set_.funnel || z >= set_.rim_z_m) return xy;
  const Eigen::Vector2d e = xy - set_.guide_xy_m;
  const double d = e.norm();
  return d <= set_.funnel_radius_m ? xy : Eigen::Vector2d(set_.guide_xy_m + e * (set_.funnel_radius_m / d));
}

bool VirtualFixtures::in_keep_out(const Eigen::Vector3d& p) const noexcept {
  for (int i = 0; i < set_.keep_out_count; ++i) {
    const auto& k = set_.keep_outs[static_cast<std::size_t>(i)];
    if (p.z() < k.top_z_m && (p.head<2>() - k.xy_m).norm() < k.radius_m) return true;
  }
  return false;
}

bool VirtualFixtures::keep_out(const Eigen::Vector3d& from, Eigen::Vector3d& to) const noexcept {
  const Eigen::Vector3d asked = to;
  for (int i = 0; i < set_.keep_out_count; ++i) {
    const auto& k = set_.keep_outs[static_cast<std::size_t>(i)];
    // On the edge (where this puts a target) counts as outside, whatever the rounding.
    const bool was_inside_circle = (from.head<2>() - k.xy_m).norm() < k.radius_m * (1.0 - 1e-9);
    if (was_inside_circle && from.z() < k.top_z_m) continue;  // installed round it: nothing to hold
    if (was_inside_circle) {
      to.z() = std::max(to.z(), k.top_z_m);  // above the part: no lower than its top
      continue;
    }
    const Eigen::Vector2d e = to.head<2>() - k.xy_m;
    const double d = e.norm();
    if (to.z() < k.top_z_m && d < k.radius_m) {
      // Below its top: on the circle's edge, radially (from its centre: the way out is outward).
      to.head<2>() = d > 0.0 ? Eigen::Vector2d(k.xy_m + e * (k.radius_m / d)) : from.head<2>();
    }
  }
  return to != asked;
}

double VirtualFixtures::lowest_z(const Eigen::Vector2d& xy, double from_z) const noexcept {
  if (!set_.guide || !set_.funnel || from_z < set_.rim_z_m) return -std::numeric_limits<double>::infinity();
  const double d = (xy - set_.guide_xy_m).norm();
  if (d <= set_.funnel_radius_m) return -std::numeric_limits<double>::infinity();
  // Off the axis: no lower than the cone, and never below the rim.
  return set_.rim_z_m + std::min(p_.funnel_height_m, (d - set_.funnel_radius_m) / tan_cone_);
}

void VirtualFixtures::rebase_energy(const Eigen::Vector2d& raw_xy, double scale) noexcept {
  observed_J_ = set_.guide ? potential_J((raw_xy - nearest_guide(raw_xy)).norm(), level_, scale) : 0.0;
  rebase_ = false;
}

Eigen::Vector2d VirtualFixtures::display_force(const Eigen::Vector2d& raw_xy,
                                               const Eigen::Vector2d& guided_xy,
                                               const Eigen::Vector2d& handle_v_m_s, double scale,
                                               double dt_s) noexcept {
  if (rebase_) rebase_energy(raw_xy, scale);
  if (!set_.guide) return Eigen::Vector2d::Zero();
  Eigen::Vector2d f = -p_.display_stiffness_N_m * (raw_xy - guided_xy) / scale;
  const double n = f.norm();
  if (n > p_.max_display_N) f *= p_.max_display_N / n;
  const Eigen::Vector2d v = handle_v_m_s.allFinite() ? handle_v_m_s : Eigen::Vector2d::Zero();
  // Passivity observer: the energy the hand has put into the fixture, from the field's energy
  // when it was installed; the controller dissipates what would take it below zero.
  double e = observed_J_ - f.dot(v) * dt_s;
  const double v2 = v.squaredNorm();
  if (e < 0.0 && v2 > 0.0) {
    const double b = -e / (v2 * dt_s);
    f -= b * v;
    dissipated_J_ -= e;
    e = 0.0;
  }
  observed_J_ = e;
  return f.allFinite() ? f : Eigen::Vector2d::Zero();
}

}  // namespace mc::teleop
