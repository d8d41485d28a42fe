#include "microcobot/motion/parallel_kinematics.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>

#include "microcobot/core/error.h"

namespace mc::motion {

namespace {

constexpr int kMaxNewtonSteps = 50;
constexpr int kMaxHalvings = 40;
constexpr double kMaxStep_m = 10e-3;
constexpr double kMaxStep_rad = 0.5;
/// Residual at which the legs are closed to rounding (q is a few mm: its ulp is ~1e-18 m).
constexpr double kResidual_m = 1e-15;
/// A step this small leaves an error of order step^2 / r, below the rounding floor.
constexpr double kFinalStep_m = 1e-10;
/// The residual a converged pose must have.
constexpr double kAccepted_m = 1e-13;

std::string describe_legs(const LegCoordinates& q) {
  return fmt::format("leg coordinates ({:.9g}, {:.9g}, {:.9g}, {:.9g}, {:.9g}, {:.9g}) mm", q[0] * 1e3,
                     q[1] * 1e3, q[2] * 1e3, q[3] * 1e3, q[4] * 1e3, q[5] * 1e3);
}

}  // namespace

ParallelKinematics::ParallelKinematics(const ParallelGeometryParams& p) : g_(p) {}

bool ParallelKinematics::closures(const PlatformTransform& T, LegClosure (&legs)[kParallelLegs],
                                  LegCoordinates& q) const noexcept {
  const double L = g_.leg_length_m;
  const double b = g_.params.base_radius_m;
  bool ok = true;
  for (int i = 0; i < kParallelLegs; ++i) {
    const LegGeometry& lg = g_.legs[i];
    LegClosure& c = legs[i];
    c.joint_m = T.d + T.R * lg.platform_m;
    c.joint_m.z() += g_.home_height_m;
    c.axis = T.R * lg.axis;
    const double n_r = c.axis.dot(lg.e_r), n_t = c.axis.dot(lg.e_t), n_z = c.axis.z();
    const double pz = c.joint_m.z();
    const double m = std::sqrt(n_r * n_r + n_t * n_t);  // |n| = 1: no overflow to guard against
    const double cc = pz * n_z / m;
    c.discriminant = (L * L - pz * pz) - cc * cc;
    if (!(c.discriminant >= 0.0) || !(m > 0.0)) {
      ok = false;
      continue;
    }
    const double lambda = -std::sqrt(c.discriminant);
    const double alpha = (cc * n_r - lambda * n_t) / m;
    const double beta = (cc * n_t + lambda * n_r) / m;
    const double u = alpha - b + c.joint_m.dot(lg.e_r);
    const double w = beta + c.joint_m.dot(lg.e_t);
    q[2 * i] = u;
    q[2 * i + 1] = w;
    c.carriage_m = (b + u) * lg.e_r + w * lg.e_t;
  }
  return ok;
}

bool ParallelKinematics::inverse(const PlatformTransform& T, LegCoordinates& q) const noexcept {
  LegClosure legs[kParallelLegs];
  return closures(T, legs, q);
}

ParallelJacobian ParallelKinematics::jacobian(const PlatformTransform& T,
                                              const LegClosure (&legs)[kParallelLegs]) const noexcept {
  ParallelJacobian J;
  for (int i = 0; i < kParallelLegs; ++i) {
    const LegGeometry& lg = g_.legs[i];
    const LegClosure& c = legs[i];
    const Eigen::Vector3d r = c.carriage_m - c.joint_m;
    const Eigen::Vector3d& n = c.axis;
    const Eigen::Vector3d rp = T.R * lg.platform_m;
    Eigen::Matrix<double, 2, 6> A;
    A.row(0) << r.transpose(), rp.cross(r).transpose();
    A.row(1) << n.transpose(), (rp + r).cross(n).transpose();
    // M^-1 = [m11 -m01; -m10 m00] / det.
    const double m00 = r.dot(lg.e_r), m01 = r.dot(lg.e_t), m10 = n.dot(lg.e_r), m11 = n.dot(lg.e_t);
    const double det = m00 * m11 - m01 * m10;
    J.row(2 * i) = (m11 * A.row(0) - m01 * A.row(1)) / det;
    J.row(2 * i + 1) = (-m10 * A.row(0) + m00 * A.row(1)) / det;
  }
  return J;
}

ParallelJacobian ParallelKinematics::jacobian(const PlatformTransform& T) const noexcept {
  LegClosure legs[kParallelLegs];
  LegCoordinates q;
  if (!closures(T, legs, q)) return ParallelJacobian::Constant(std::nan(""));
  return jacobian(T, legs);
}

double ParallelKinematics::conditioning(const ParallelJacobian& J) const noexcept {
  if (!J.allFinite()) return 0.0;
  ParallelJacobian Jn = J;
  Jn.rightCols<3>() /= g_.params.platform_radius_m;
  const Eigen::JacobiSVD<ParallelJacobian> svd(Jn);
  const auto& s = svd.singularValues();
  if (!(s[0] > 0.0)) return 0.0;
  return s[5] / s[0];
}

bool ParallelKinematics::conditioning_at_least(const ParallelJacobian& J, double threshold) const noexcept {
  if (!J.allFinite()) return false;
  ParallelJacobian Jn = J;
  Jn.rightCols<3>() /= g_.params.platform_radius_m;
  // sigma_max <= |Jn|_F and sigma_min >= 1 / |Jn^-1|_F: a lower bound of the conditioning that
  // costs an LU, not an SVD. Only when it does not decide is the SVD computed.
  const Eigen::PartialPivLU<ParallelJacobian> lu(Jn);
  const ParallelJacobian inv = lu.inverse();
  if (inv.allFinite() && 1.0 / (Jn.norm() * inv.norm()) >= threshold) return true;
  return conditioning(J) >= threshold;
}

double ParallelKinematics::conditioning(const PlatformTransform& T) const noexcept {
  return conditioning(jacobian(T));
}

void ParallelKinematics::joint_angles(const PlatformTransform& T, const LegClosure (&legs)[kParallelLegs],
                                      double (&spherical)[kParallelLegs],
                                      double (&revolute)[kParallelLegs]) const noexcept {
  for (int i = 0; i < kParallelLegs; ++i) {
    const LegGeometry& lg = g_.legs[i];
    const Eigen::Vector3d leg = (legs[i].joint_m - legs[i].carriage_m) / g_.leg_length_m;
    spherical[i] = std::atan2(leg.cross(lg.home_leg).norm(), leg.dot(lg.home_leg));
    const Eigen::Vector3d in_platform = T.R.transpose() * leg;  // the leg seen from the platform
    revolute[i] = std::atan2(lg.home_leg.cross(in_platform).dot(lg.axis), lg.home_leg.dot(in_platform));
  }
}

ForwardResult ParallelKinematics::forward(const LegCoordinates& q, const PlatformTransform& seed) const {
  const double half = 0.5 * g_.params.stroke_m;
  if (!q.allFinite()) throw InvalidInput("forward kinematics: " + describe_legs(q) + " are not finite");
  if (q.lpNorm<Eigen::Infinity>() > half) {
    throw InvalidInput(
        fmt::format("forward kinematics: {} beyond the stroke +-{:g} mm", describe_legs(q), half * 1e3));
  }
  const auto fail = [&](const std::string& why) {
    throw ComputationFailed("forward kinematics of " + describe_legs(q) + ": " + why);
  };
  const double r_p = g_.params.platform_radius_m;

  ForwardResult out;
  out.T = seed;
  LegClosure legs[kParallelLegs];
  LegCoordinates q_now;
  if (!closures(out.T, legs, q_now)) fail("the seed pose's legs do not close");
  bool converged = false;
  while (!converged) {
    const LegCoordinates residual = q_now - q;
    if (residual.lpNorm<Eigen::Infinity>() <= kResidual_m) break;
    if (out.iterations == kMaxNewtonSteps)
      fail(fmt::format("no convergence in {} Newton steps", kMaxNewtonSteps));
    const ParallelJacobian J = jacobian(out.T, legs);
    const LegCoordinates delta = J.partialPivLu().solve(residual);
    if (!delta.allFinite()) fail("singular Jacobian on the way");
    const double step_d = delta.head<3>().norm(), step_t = delta.tail<3>().norm();
    double s =
        std::min({1.0, kMaxStep_m / std::max(step_d, 1e-300), kMaxStep_rad / std::max(step_t, 1e-300)});
    ++out.iterations;
    PlatformTransform trial;
    int halvings = 0;
    for (;; ++halvings) {
      if (halvings == kMaxHalvings) fail("every Newton step leaves the legs' reach");
      const Eigen::Vector3d turn = -s * delta.tail<3>();
      const double angle = turn.norm();
      trial.R = angle > 0.0
                    ? Eigen::Matrix3d(Eigen::AngleAxisd(angle, turn / angle).toRotationMatrix() * out.T.R)
                    : out.T.R;
      trial.d = out.T.d - s * delta.head<3>();
      if (closures(trial, legs, q_now)) break;
      s *= 0.5;
    }
    out.T = trial;
    converged = halvings == 0 && s == 1.0 && step_d + r_p * step_t <= kFinalStep_m;
  }
  if ((q_now - q).lpNorm<Eigen::Infinity>() > kAccepted_m) fail("the legs' residual stays above 1e-13 m");
  if (!conditioning_at_least(jacobian(out.T, legs), g_.params.min_conditioning))
    fail("the solution is singular");
  double sph[kParallelLegs], rev[kParallelLegs];
  joint_angles(out.T, legs, sph, rev);
  for (int i = 0; i < kParallelLegs; ++i) {
    if (sph[i] > g_.params.spherical_limit_rad || std::abs(rev[i]) > g_.params.revolute_limit_rad) {
      fail(fmt::format("the solution has leg {}'s passive joints beyond their limits (another assembly mode)",
                       i));
    }
  }
  return out;
}

}  // namespace mc::motion
