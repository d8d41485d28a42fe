#pragma once
/// @file
/// Poses of a 6-DOF positioner's platform and the two conventions its users script them in.
///
/// The model works on the platform's rigid transform T = (R, d) relative to its home frame {H}:
/// a point q of the platform (in the platform's frame {P}, which coincides with {H} at home) is
/// at x = R q + d in {H}. Users give a pose as three translations and three angles about a pivot
/// point c; the conversions below are exact (closed form both ways, no iteration).
///
/// Rotation conventions (SI: angles in rad; deg only at the command line):
///  - SmarPod (x, y, z, rx, ry, rz): R = Rz(rz) Ry(ry) Rx(rx), i.e. rotations about the fixed
///    axes x, then y, then z. Its inverse: ry = asin(-R20), rx = atan2(R21, R22),
///    rz = atan2(R10, R00), unique for |ry| < pi/2.
///  - PI hexapod (X, Y, Z, U, V, W): rotations "calculated from the individual rotations in the
///    order U -> V -> W" about axes that "move together with the platform" (PI's hexapod
///    manuals, e.g. H-820 MS207E §3.7.4 "Motion"): intrinsic rotations about x, then the moved
///    y, then the twice-moved z, R = Rx(U) Ry(V) Rz(W). Its inverse: V = asin(R02),
///    U = atan2(-R12, R22), W = atan2(-R01, R00), unique for |V| < pi/2.
///
/// Pivot point c (the centre of the rotations), two modes:
///  - relative: c is a point of the platform (given in {P}) and moves with its translation:
///    x = R (q - c) + c + t, so d = t + (I - R) c. PI's hexapods behave so ("the center of
///    rotation always moves together with the platform"; translations in the fixed frame).
///  - fixed: c stays where it is in {H} whatever the translation: the platform is translated by
///    t, then turned about c: x = R (q + t - c) + c, so d = R t + (I - R) c, and back
///    t = R^T (d - (I - R) c).
/// With c = 0 both modes read d = t (relative) or d = R t (fixed).

#include <array>
#include <string>

#include <Eigen/Core>

namespace mc::motion {

/// The platform's rigid transform relative to its home frame: x_H = R q_P + d.
struct PlatformTransform {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d d = Eigen::Vector3d::Zero();  ///< [m]
};

enum class PivotMode { kRelative, kFixed };
PivotMode parse_pivot_mode(const std::string& name);  ///< "relative" | "fixed", else UsageError
std::string to_string(PivotMode m);

struct Pivot {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();  ///< in {P} (relative) or {H} (fixed)
  PivotMode mode = PivotMode::kRelative;
};

/// SmarPod's pose: translations [m], rotations [rad], R = Rz(rz) Ry(ry) Rx(rx).
struct SmarPodPose {
  double x = 0.0, y = 0.0, z = 0.0;
  double rx = 0.0, ry = 0.0, rz = 0.0;
  std::array<double, 6> as_array() const { return {x, y, z, rx, ry, rz}; }
  static SmarPodPose from_array(const std::array<double, 6>& a) {
    return {a[0], a[1], a[2], a[3], a[4], a[5]};
  }
};

/// PI's hexapod pose: translations [m], rotations [rad] U -> V -> W about moving axes,
/// R = Rx(U) Ry(V) Rz(W).
struct PiPose {
  double X = 0.0, Y = 0.0, Z = 0.0;
  double U = 0.0, V = 0.0, W = 0.0;
};

Eigen::Matrix3d rot_x(double a);
Eigen::Matrix3d rot_y(double a);
Eigen::Matrix3d rot_z(double a);

/// R = Rz(rz) Ry(ry) Rx(rx).
Eigen::Matrix3d smarpod_rotation(double rx, double ry, double rz);
/// (rx, ry, rz) of R, ry in [-pi/2, pi/2]; at |ry| = pi/2 (gimbal lock) rz = 0 by convention.
Eigen::Vector3d smarpod_angles(const Eigen::Matrix3d& R);
/// R = Rx(U) Ry(V) Rz(W).
Eigen::Matrix3d pi_rotation(double u, double v, double w);
/// (U, V, W) of R, V in [-pi/2, pi/2]; at |V| = pi/2 W = 0 by convention.
Eigen::Vector3d pi_angles(const Eigen::Matrix3d& R);

/// exp([w]x) (Rodrigues): the rotation by |w| about w; the identity for w = 0.
Eigen::Matrix3d exp_so3(const Eigen::Vector3d& w) noexcept;
/// log(R): R's axis-angle vector, |w| in [0, pi].
Eigen::Vector3d log_so3(const Eigen::Matrix3d& R) noexcept;

/// The transform of a SmarPod pose about `pivot` (d = t + (I-R)c or R t + (I-R)c), and back.
PlatformTransform to_transform(const SmarPodPose& p, const Pivot& pivot = {});
SmarPodPose to_smarpod(const PlatformTransform& T, const Pivot& pivot = {});
/// The transform of a PI pose about the pivot `pivot_m` (in {P}, moving with the platform:
/// PI's only mode), and back.
PlatformTransform to_transform(const PiPose& p, const Eigen::Vector3d& pivot_m = Eigen::Vector3d::Zero());
PiPose to_pi(const PlatformTransform& T, const Eigen::Vector3d& pivot_m = Eigen::Vector3d::Zero());

/// True when every number of the pose is finite.
bool is_finite(const SmarPodPose& p) noexcept;
/// "(x, y, z) mm, (rx, ry, rz) deg" with 6 significant digits: names a pose in messages.
std::string describe(const SmarPodPose& p);

}  // namespace mc::motion
