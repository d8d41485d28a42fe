#pragma once
/// @file
/// Kinematics of the 3 x PPSR parallel positioner (parallel_geometry.h): closed-form inverse
/// kinematics, its Jacobian, a conditioning measure, and forward kinematics by Newton's method
/// on the inverse. A const model: every call is a pure function of its arguments.
///
/// Inverse kinematics, leg i, for the platform transform T = (R, d) (pose.h). The revolute joint's
/// centre and axis in {B}: P = (h + o) e_z + d + R p_i, n = R a_i. The spherical joint's centre
/// B = b e_r + u e_r + w e_t (z = 0) must close the leg: |B - P| = L (rigid leg) and
/// (B - P) . n = 0 (the leg turns about n, so it stays perpendicular to it). In the carriage's
/// coordinates (alpha, beta) = ((B - P) . e_r, (B - P) . e_t), with P_z the joint's height:
///   alpha n_r + beta n_t = P_z n_z            (a line; n_r = n . e_r, n_t = n . e_t)
///   alpha^2 + beta^2 = rho^2 = L^2 - P_z^2    (a circle)
/// With m = |(n_r, n_t)|, k = (n_r, n_t) / m, k_perp = (-n_t, n_r) / m, c = P_z n_z / m:
///   (alpha, beta) = c k + lambda k_perp,  lambda = -sqrt(rho^2 - c^2),
///   u = alpha - (b - P . e_r),  w = beta + P . e_t.
/// The root lambda < 0 is the leg's assembly (at home: alpha = b - r > 0, the carriage outside the
/// platform's joint); the other root is the leg folded inwards. rho^2 - c^2 < 0: the leg cannot
/// close (the pose is out of its reach); = 0: both roots meet (a singular pose).
///
/// Jacobian: for a small motion of the platform, (delta d, delta theta) with
/// R' = exp([delta theta]x) R, each leg's two closure equations differentiate to
///   M_i (du, dw)^T = A_i (delta d, delta theta)^T,
///   M_i = [ r . e_r   r . e_t ]     A_i = [ r^T   ((R p_i) x r)^T       ]
///         [ n . e_r   n . e_t ],          [ n^T   ((R p_i + r) x n)^T ]
/// with r = B - P; J = blockdiag(M_i)^-1 A (6 x 6, dq = J twist). det M_i = 0 is the leg's
/// closure at its double root (an inverse-kinematic singularity); det A = 0 is where the six
/// positioners held no longer hold the platform (a direct-kinematic singularity).
///
/// Conditioning: the reciprocal condition number sigma_min / sigma_max of J with its rotation
/// columns scaled by the platform radius r (so that both halves are metres of leg per metre of
/// platform motion): 1 is isotropic, 0 is singular; 0 too when a leg does not close.
///
/// Forward kinematics: Newton's method on q(T) - q = 0 with J, stepping on the rotation group
/// (R <- exp(-[delta theta]x) R, no Euler-angle singularity), each step limited to 10 mm and
/// 0.5 rad and halved while the trial pose's legs do not close. Converged when the legs' residual
/// is below 1e-15 m, or after a full step below 1e-10 m (Newton's error after it is of order
/// step^2 / r, below the rounding floor); the result must then close within 1e-13 m, be
/// non-singular and have its passive joints within their limits (a solution outside them is
/// another assembly mode of the same leg coordinates, not the positioner's pose), else
/// mc::ComputationFailed naming the leg coordinates.
/// Convergence domain: seed and solution in the reachable workspace (parallel_workspace.h).
/// tests/motion/parallel_kinematics_test.cc and bench/positioner_bench.cc sample it: from home to
/// random reachable poses up to 4 mm (3 mm in z) and 10 deg a coordinate away in at most 10 steps;
/// from the previous pose of a random walk of 0.2 mm and 1 deg a coordinate a step in at most 5.

#include <Eigen/Core>

#include "microcobot/motion/parallel_geometry.h"
#include "microcobot/motion/pose.h"

namespace mc::motion {

using LegCoordinates = Eigen::Matrix<double, 6, 1>;    ///< (u_0, w_0, u_1, w_1, u_2, w_2) [m]
using ParallelJacobian = Eigen::Matrix<double, 6, 6>;  ///< dq / (delta d, delta theta)

/// One leg's closure at a pose: where its joints are and how its passive joints stand.
struct LegClosure {
  Eigen::Vector3d joint_m;     ///< P: the revolute joint's centre, {B}
  Eigen::Vector3d carriage_m;  ///< B: the spherical joint's centre, {B}
  Eigen::Vector3d axis;        ///< n: the revolute joint's axis, {B}
  double discriminant = 0.0;   ///< rho^2 - c^2 [m^2]: < 0 no closure, 0 double root
};

struct ForwardResult {
  PlatformTransform T;
  int iterations = 0;  ///< Newton steps taken
};

class ParallelKinematics {
 public:
  explicit ParallelKinematics(const ParallelGeometryParams& p = {});

  const ParallelGeometry& geometry() const noexcept { return g_; }
  const ParallelGeometryParams& params() const noexcept { return g_.params; }

  /// Closed-form IK: the leg coordinates of `T`; false (q unspecified) when a leg cannot close.
  /// Does not check strokes or joint limits (parallel_workspace.h does). Never allocates.
  bool inverse(const PlatformTransform& T, LegCoordinates& q) const noexcept;
  /// The legs' closures at `T` (for the Jacobian, joint limits and drawings); false as inverse().
  bool closures(const PlatformTransform& T, LegClosure (&legs)[kParallelLegs],
                LegCoordinates& q) const noexcept;
  /// J at `T` (from its closures); entries are infinite or NaN where a leg does not close or
  /// det M_i = 0.
  ParallelJacobian jacobian(const PlatformTransform& T) const noexcept;
  ParallelJacobian jacobian(const PlatformTransform& T,
                            const LegClosure (&legs)[kParallelLegs]) const noexcept;
  /// sigma_min / sigma_max of J with rotation columns scaled by r; 0 where J is not finite.
  double conditioning(const PlatformTransform& T) const noexcept;
  double conditioning(const ParallelJacobian& J) const noexcept;
  /// conditioning(J) >= threshold, without the SVD where a bound decides (the FK's check).
  bool conditioning_at_least(const ParallelJacobian& J, double threshold) const noexcept;
  /// The passive joints' angles from home, per leg: the spherical joint's cone angle and the
  /// revolute's signed angle [rad].
  void joint_angles(const PlatformTransform& T, const LegClosure (&legs)[kParallelLegs],
                    double (&spherical)[kParallelLegs], double (&revolute)[kParallelLegs]) const noexcept;

  /// FK by Newton from `seed` (the previous pose, or home). Throws mc::InvalidInput for leg
  /// coordinates that are not finite or beyond the stroke, mc::ComputationFailed when it does not
  /// converge to a pose of the positioner (the header's criteria).
  ForwardResult forward(const LegCoordinates& q, const PlatformTransform& seed = {}) const;

 private:
  ParallelGeometry g_;
};

}  // namespace mc::motion
