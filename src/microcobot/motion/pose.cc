#include "microcobot/motion/pose.h"

#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <Eigen/Geometry>

#include "microcobot/core/error.h"

namespace mc::motion {

PivotMode parse_pivot_mode(const std::string& name) {
  if (name == "relative") return PivotMode::kRelative;
  if (name == "fixed") return PivotMode::kFixed;
  throw UsageError("--pivot-mode must be relative or fixed (got '" + name + "')");
}

std::string to_string(PivotMode m) { return m == PivotMode::kFixed ? "fixed" : "relative"; }

Eigen::Matrix3d rot_x(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << 1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c;
  return r;
}

Eigen::Matrix3d rot_y(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c;
  return r;
}

Eigen::Matrix3d rot_z(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0;
  return r;
}

Eigen::Matrix3d smarpod_rotation(double rx, double ry, double rz) {
  // Rz Ry Rx written out (one matrix, no products): the IK's hot path.
  const double cx = std::cos(rx), sx = std::sin(rx);
  const double cy = std::cos(ry), sy = std::sin(ry);
  const double cz = std::cos(rz), sz = std::sin(rz);
  Eigen::Matrix3d r;
  r << cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx,  //
      sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx,   //
      -sy, cy * sx, cy * cx;
  return r;
}

Eigen::Vector3d smarpod_angles(const Eigen::Matrix3d& R) {
  // R20 = -sin ry, (R21, R22) = cos ry (sin rx, cos rx), (R10, R00) = cos ry (sin rz, cos rz).
  const double c = std::hypot(R(2, 1), R(2, 2));
  const double ry = std::atan2(-R(2, 0), c);
  if (c < 1e-12) {
    // Gimbal lock: only rx -+ rz is defined; rz = 0 takes it all into rx.
    return {std::atan2(-R(1, 2), R(1, 1)), ry, 0.0};
  }
  return {std::atan2(R(2, 1), R(2, 2)), ry, std::atan2(R(1, 0), R(0, 0))};
}

Eigen::Matrix3d pi_rotation(double u, double v, double w) { return rot_x(u) * rot_y(v) * rot_z(w); }

Eigen::Vector3d pi_angles(const Eigen::Matrix3d& R) {
  // R02 = sin V, (-R12, R22) = cos V (sin U, cos U), (-R01, R00) = cos V (sin W, cos W).
  const double c = std::hypot(R(1, 2), R(2, 2));
  const double v = std::atan2(R(0, 2), c);
  if (c < 1e-12) return {std::atan2(R(2, 1), R(1, 1)), v, 0.0};
  return {std::atan2(-R(1, 2), R(2, 2)), v, std::atan2(-R(0, 1), R(0, 0))};
}

namespace {

/// d of a pose's translation t and rotation R about the pivot (the header's equations).
Eigen::Vector3d pivot_displacement(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Pivot& pivot) {
  const Eigen::Vector3d turn = pivot.point_m - R * pivot.point_m;  // (I - R) c
  return pivot.mode == PivotMode::kFixed ? Eigen::Vector3d(R * t + turn) : Eigen::Vector3d(t + turn);
}

Eigen::Vector3d pivot_translation(const PlatformTransform& T, const Pivot& pivot) {
  const Eigen::Vector3d rest = T.d - (pivot.point_m - T.R * pivot.point_m);  // d - (I - R) c
  return pivot.mode == PivotMode::kFixed ? Eigen::Vector3d(T.R.transpose() * rest) : rest;
}

}  // namespace

Eigen::Matrix3d exp_so3(const Eigen::Vector3d& w) noexcept {
  const double a = w.norm();
  if (a < 1e-300) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(a, w / a).toRotationMatrix();
}

Eigen::Vector3d log_so3(const Eigen::Matrix3d& R) noexcept {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

PlatformTransform to_transform(const SmarPodPose& p, const Pivot& pivot) {
  PlatformTransform T;
  T.R = smarpod_rotation(p.rx, p.ry, p.rz);
  T.d = pivot_displacement(T.R, {p.x, p.y, p.z}, pivot);
  return T;
}

SmarPodPose to_smarpod(const PlatformTransform& T, const Pivot& pivot) {
  const Eigen::Vector3d t = pivot_translation(T, pivot);
  const Eigen::Vector3d a = smarpod_angles(T.R);
  return {t.x(), t.y(), t.z(), a.x(), a.y(), a.z()};
}

PlatformTransform to_transform(const PiPose& p, const Eigen::Vector3d& pivot_m) {
  PlatformTransform T;
  T.R = pi_rotation(p.U, p.V, p.W);
  T.d = pivot_displacement(T.R, {p.X, p.Y, p.Z}, {pivot_m, PivotMode::kRelative});
  return T;
}

PiPose to_pi(const PlatformTransform& T, const Eigen::Vector3d& pivot_m) {
  const Eigen::Vector3d t = pivot_translation(T, {pivot_m, PivotMode::kRelative});
  const Eigen::Vector3d a = pi_angles(T.R);
  return {t.x(), t.y(), t.z(), a.x(), a.y(), a.z()};
}

bool is_finite(const SmarPodPose& p) noexcept {
  for (double v : p.as_array()) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

std::string describe(const SmarPodPose& p) {
  constexpr double kDeg = 180.0 / std::numbers::pi;
  return fmt::format("({:.6g}, {:.6g}, {:.6g}) mm, ({:.6g}, {:.6g}, {:.6g}) deg", p.x * 1e3, p.y * 1e3,
                     p.z * 1e3, p.rx * kDeg, p.ry * kDeg, p.rz * kDeg);
}

}  // namespace mc::motion
