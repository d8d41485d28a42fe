// The 6-DOF parallel positioner's kinematics (3 x PPSR, parallel_kinematics.h): the closed-form
// inverse against the legs' closure equations, the forward kinematics by Newton against the
// inverse over seeded random reachable poses, the Jacobian against finite differences, and the
// refusals (singular, unreachable, NaN, leg coordinates that are no pose).
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "microcobot/core/error.h"
#include "microcobot/motion/parallel_kinematics.h"
#include "microcobot/motion/parallel_workspace.h"

namespace mc::motion {
namespace parallel_kinematics_test {

constexpr double kDeg = M_PI / 180.0;

/// The rotation angle of R_a R_b^T [rad].
double rotation_error(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a * b.transpose()).angle();
}

/// `n` seeded random reachable poses, uniform in a box that holds the workspace's core.
std::vector<SmarPodPose> random_reachable_poses(const ParallelKinematics& k, int n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> t(-4e-3, 4e-3), z(-3e-3, 3e-3), a(-10 * kDeg, 10 * kDeg);
  std::vector<SmarPodPose> poses;
  while (static_cast<int>(poses.size()) < n) {
    const SmarPodPose p{t(rng), t(rng), z(rng), a(rng), a(rng), a(rng)};
    if (check_pose(k, p).ok()) poses.push_back(p);
  }
  return poses;
}

TEST(ParallelKinematics, HomeIsMidStrokeWithEveryLegAt45Degrees) {
  const ParallelKinematics k;
  LegCoordinates q;
  ASSERT_TRUE(k.inverse({}, q));
  EXPECT_LT(q.lpNorm<Eigen::Infinity>(), 1e-18);
  EXPECT_NEAR(k.geometry().leg_length_m, std::hypot(20e-3, 20e-3), 1e-18);
  for (const auto& leg : k.geometry().legs) EXPECT_NEAR(leg.home_leg.z(), std::sqrt(0.5), 1e-15);
  EXPECT_GT(k.conditioning(PlatformTransform{}), k.params().min_conditioning);
}

TEST(ParallelKinematics, InverseClosesEveryLegRigidAndPerpendicularToItsRevoluteAxis) {
  const ParallelKinematics k;
  for (const SmarPodPose& p : random_reachable_poses(k, 500, 11)) {
    const PlatformTransform T = to_transform(p);
    LegClosure legs[kParallelLegs];
    LegCoordinates q;
    ASSERT_TRUE(k.closures(T, legs, q));
    for (int i = 0; i < kParallelLegs; ++i) {
      const auto& g = k.geometry().legs[i];
      // The joints recomputed from the pose and the coordinates, not taken from the closure.
      const Eigen::Vector3d P = T.d + T.R * g.platform_m + Eigen::Vector3d(0, 0, k.geometry().home_height_m);
      const Eigen::Vector3d B = g.base_m + q[2 * i] * g.e_r + q[2 * i + 1] * g.e_t;
      EXPECT_NEAR((B - P).norm(), k.geometry().leg_length_m, 1e-15);
      EXPECT_NEAR((B - P).dot(T.R * g.axis), 0.0, 1e-15);
      EXPECT_NEAR(B.z(), 0.0, 0.0);
    }
  }
}

TEST(ParallelKinematics, ForwardRecoversTenThousandRandomPosesWithin1e12MetreAnd1e12Radian) {
  const ParallelKinematics k;
  const auto poses = random_reachable_poses(k, 10000, 2026);
  double worst_m = 0.0, worst_rad = 0.0;
  for (const SmarPodPose& p : poses) {
    const PlatformTransform T = to_transform(p);
    LegCoordinates q;
    ASSERT_TRUE(k.inverse(T, q));
    const ForwardResult f = k.forward(q);  // from home
    worst_m = std::max(worst_m, (f.T.d - T.d).lpNorm<Eigen::Infinity>());
    worst_rad = std::max(worst_rad, rotation_error(f.T.R, T.R));
    const SmarPodPose back = to_smarpod(f.T);
    for (int j = 0; j < 6; ++j) ASSERT_NEAR(back.as_array()[j], p.as_array()[j], 1e-12) << describe(p);
  }
  EXPECT_LE(worst_m, 1e-12);
  EXPECT_LE(worst_rad, 1e-12);
}

TEST(ParallelKinematics, ForwardFromThePreviousPoseConvergesInAtMostFiveStepsIn999Permille) {
  // A seeded random walk through the workspace, each pose up to 0.2 mm and 1 deg per coordinate
  // from the previous one (a 1 kHz loop at 200 mm/s, beyond any stick-slip positioner's speed),
  // each solved from the previous solution.
  const ParallelKinematics k;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> dt(-0.2e-3, 0.2e-3), da(-1 * kDeg, 1 * kDeg);
  SmarPodPose pose;
  PlatformTransform previous;
  int within_five = 0, most = 0;
  for (int n = 0; n < 10000; ++n) {
    SmarPodPose next;
    do {
      next = {pose.x + dt(rng),  pose.y + dt(rng),  pose.z + dt(rng),
              pose.rx + da(rng), pose.ry + da(rng), pose.rz + da(rng)};
    } while (!check_pose(k, next).ok());
    pose = next;
    LegCoordinates q;
    ASSERT_TRUE(k.inverse(to_transform(pose), q));
    const ForwardResult f = k.forward(q, previous);
    within_five += f.iterations <= 5 ? 1 : 0;
    most = std::max(most, f.iterations);
    ASSERT_LE((f.T.d - to_transform(pose).d).lpNorm<Eigen::Infinity>(), 1e-12);
    previous = f.T;
  }
  EXPECT_GE(within_five, 9990) << "most steps: " << most;
}

TEST(ParallelKinematics, ForwardFromHomeConvergesAcrossTheSampledWorkspaceInAtMostTenSteps) {
  // The convergence domain: from the home seed to any sampled reachable pose (up to 4 mm, 3 mm in
  // z and 10 deg a coordinate away), the step limits and halving keep Newton's method on the legs'
  // branch.
  const ParallelKinematics k;
  int most = 0;
  for (const SmarPodPose& p : random_reachable_poses(k, 2000, 17)) {
    LegCoordinates q;
    ASSERT_TRUE(k.inverse(to_transform(p), q));
    most = std::max(most, k.forward(q).iterations);
  }
  EXPECT_LE(most, 10);
}

TEST(ParallelKinematics, JacobianMatchesCentralFiniteDifferencesOfTheInverse) {
  const ParallelKinematics k;
  const double h = 1e-7;
  for (const SmarPodPose& p : random_reachable_poses(k, 200, 3)) {
    const PlatformTransform T = to_transform(p);
    const ParallelJacobian J = k.jacobian(T);
    for (int c = 0; c < 6; ++c) {
      PlatformTransform plus = T, minus = T;
      if (c < 3) {
        plus.d[c] += h;
        minus.d[c] -= h;
      } else {
        const Eigen::Vector3d axis = Eigen::Vector3d::Unit(c - 3);
        plus.R = Eigen::AngleAxisd(h, axis).toRotationMatrix() * T.R;
        minus.R = Eigen::AngleAxisd(-h, axis).toRotationMatrix() * T.R;
      }
      LegCoordinates qp, qm;
      ASSERT_TRUE(k.inverse(plus, qp) && k.inverse(minus, qm));
      const LegCoordinates fd = (qp - qm) / (2 * h);
      const double scale = c < 3 ? 1.0 : k.params().platform_radius_m;  // m/m and m/rad alike
      for (int r = 0; r < 6; ++r) EXPECT_NEAR(J(r, c), fd[r], 1e-6 * std::max(1.0, std::abs(fd[r])) * scale);
    }
  }
}

TEST(ParallelKinematics, LegsStandingVerticalIsSingularAndHigherIsOutOfReach) {
  const ParallelKinematics k;
  const double vertical = k.geometry().leg_length_m - k.params().joint_height_m;  // 8.28 mm of lift
  // Just below: the legs nearly vertical, their closure's two roots about to meet.
  const ReachCheck near = check_pose(k, SmarPodPose{0, 0, vertical - 1e-9, 0, 0, 0});
  EXPECT_EQ(near.reach, Reach::kSingular) << near.detail;
  EXPECT_LT(near.conditioning, 1e-3);
  const ReachCheck above = check_pose(k, SmarPodPose{0, 0, vertical + 1e-6, 0, 0, 0});
  EXPECT_EQ(above.reach, Reach::kOutOfReach) << above.detail;
  try {
    inverse_checked(k, SmarPodPose{0, 0, vertical - 1e-9, 0, 0, 0});
    FAIL() << "a singular pose was accepted";
  } catch (const PoseUnreachable& e) {
    EXPECT_EQ(e.reason(), Reach::kSingular);
    EXPECT_NE(std::string(e.what()).find("unreachable: singular"), std::string::npos) << e.what();
  }
}

TEST(ParallelKinematics, ConditioningVanishesAsTheLiftBringsTheLegsVertical) {
  const ParallelKinematics k;
  const double vertical = k.geometry().leg_length_m - k.params().joint_height_m;
  double previous = 1.0;
  for (double f : {0.9, 0.99, 0.999, 0.99999}) {
    const double c = k.conditioning(to_transform(SmarPodPose{0, 0, f * vertical, 0, 0, 0}));
    EXPECT_LT(c, previous) << "lift " << f * vertical;
    previous = c;
  }
  EXPECT_LT(previous, 0.01);
}

TEST(ParallelKinematics, TheForwardKinematicsSingularityTestAgreesWithTheConditioning) {
  // conditioning_at_least() decides by a bound where it can; its answer must be the SVD's.
  const ParallelKinematics k;
  const double vertical = k.geometry().leg_length_m - k.params().joint_height_m;
  std::vector<SmarPodPose> poses = random_reachable_poses(k, 300, 23);
  for (double f : {0.9, 0.99, 0.999, 0.9999, 0.999999}) poses.push_back({0, 0, f * vertical, 0, 0, 0});
  int below = 0;
  for (const SmarPodPose& p : poses) {
    const ParallelJacobian J = k.jacobian(to_transform(p));
    for (double threshold : {0.02, 0.1, 0.3, 0.4}) {
      const bool expected = k.conditioning(J) >= threshold;
      EXPECT_EQ(k.conditioning_at_least(J, threshold), expected) << describe(p) << " threshold " << threshold;
      below += expected ? 0 : 1;
    }
  }
  EXPECT_GT(below, 5);  // both answers were asked for
}

TEST(ParallelKinematics, PoseBeyondAStrokeIsRefusedNamingTheLegAndPositioner) {
  const ParallelKinematics k;
  const SmarPodPose far{9e-3, 0, 0, 0, 0, 0};
  const ReachCheck c = check_pose(k, far);
  EXPECT_EQ(c.reach, Reach::kStrokeLimit);
  EXPECT_NE(c.detail.find("beyond its stroke +-6 mm"), std::string::npos) << c.detail;
  try {
    inverse_checked(k, far);
    FAIL() << "an unreachable pose was accepted";
  } catch (const PoseUnreachable& e) {
    EXPECT_EQ(e.exit_code(), ExitCode::kInvalidInput);
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("pose (9, 0, 0) mm, (0, 0, 0) deg unreachable: stroke limit"),
              std::string::npos)
        << e.what();
  }
}

TEST(ParallelKinematics, NaNPoseAndNaNLegCoordinatesAreRefused) {
  const ParallelKinematics k;
  EXPECT_EQ(check_pose(k, SmarPodPose{0, std::nan(""), 0, 0, 0, 0}).reach, Reach::kNotFinite);
  EXPECT_EQ(check_pose(k, SmarPodPose{0, 0, 0, 0, INFINITY, 0}).reach, Reach::kNotFinite);
  EXPECT_THROW(inverse_checked(k, SmarPodPose{0, 0, 0, std::nan(""), 0, 0}), PoseUnreachable);
  LegCoordinates q = LegCoordinates::Zero();
  q[3] = std::nan("");
  EXPECT_THROW(k.forward(q), InvalidInput);
  q[3] = 7e-3;  // beyond the +-6 mm stroke
  EXPECT_THROW(k.forward(q), InvalidInput);
}

TEST(ParallelKinematics, ForwardEitherFailsOrReturnsThePoseOfTheLegCoordinates) {
  // Leg coordinates drawn anywhere in the stroke box: many are no pose of the positioner (their
  // platform would need joints beyond their limits). FK must throw for those, never return a pose
  // whose inverse is not the input.
  const ParallelKinematics k;
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> u(-6e-3, 6e-3);
  int solved = 0, refused = 0;
  for (int n = 0; n < 2000; ++n) {
    LegCoordinates q;
    for (int j = 0; j < 6; ++j) q[j] = u(rng);
    try {
      const ForwardResult f = k.forward(q);
      LegCoordinates back;
      ASSERT_TRUE(k.inverse(f.T, back));
      ASSERT_LE((back - q).lpNorm<Eigen::Infinity>(), 1e-13);
      const ReachCheck c = check_pose(k, f.T);
      ASSERT_TRUE(c.ok()) << to_string(c.reach) << ": " << c.detail;
      ++solved;
    } catch (const ComputationFailed& e) {
      EXPECT_EQ(std::string(e.what()).find("forward kinematics of leg coordinates ("), 0u) << e.what();
      ++refused;
    }
  }
  EXPECT_GT(solved, 100);
  EXPECT_GT(refused, 0);
}

TEST(ParallelKinematics, RotationRangesAtHomeAreMirrorSymmetricAboutLegZerosPlane) {
  // The structure is its own mirror image in the plane x = 0 (leg 0 on +y, legs 1 and 2 swap):
  // ry and rz turn into their opposites, so their ranges at home are symmetric.
  const ParallelKinematics k;
  for (int axis : {1, 2}) {
    const RotationRange r = rotation_range(k, SmarPodPose{}, axis);
    EXPECT_NEAR(r.min_rad, -r.max_rad, 1e-8) << "axis " << axis;
    EXPECT_GT(r.max_rad, 2 * kDeg);
  }
  for (int axis : {0, 1, 2}) {
    const RotationRange r = rotation_range(k, SmarPodPose{}, axis);
    EXPECT_NE(r.max_reason, Reach::kReachable);
    EXPECT_NE(r.min_reason, Reach::kReachable);
    SmarPodPose inside, beyond;
    auto a = inside.as_array();
    a[3 + axis] = r.max_rad - 1e-8;
    EXPECT_TRUE(check_pose(k, SmarPodPose::from_array(a)).ok());
    a[3 + axis] = r.max_rad + 1e-8;
    EXPECT_EQ(check_pose(k, SmarPodPose::from_array(a)).reach, r.max_reason);
  }
}

TEST(ParallelKinematics, WorkspaceSliceMarksEachPointWithItsReach) {
  const ParallelKinematics k;
  SliceSpec s;
  s.axis_a = 0;
  s.axis_b = 1;
  s.lo_a = s.lo_b = -10e-3;
  s.hi_a = s.hi_b = 10e-3;
  s.n_a = s.n_b = 21;
  const CsvTable t = workspace_slice(k, s);
  ASSERT_EQ(t.rows(), 441u);
  int reachable = 0;
  for (std::size_t r = 0; r < t.rows(); ++r) {
    const SmarPodPose p{t.column("x_m")[r], t.column("y_m")[r], 0, 0, 0, 0};
    const ReachCheck c = check_pose(k, p);
    EXPECT_EQ(t.column("reach")[r], static_cast<double>(c.reach));
    reachable += c.ok() ? 1 : 0;
  }
  EXPECT_GT(reachable, 10);
  EXPECT_LT(reachable, 441);               // the corners at 10 mm are beyond the strokes
  EXPECT_EQ(t.column("reach")[220], 0.0);  // the centre is home
  s.axis_b = 0;
  EXPECT_THROW(workspace_slice(k, s), InvalidParams);
}

TEST(ParallelGeometry, ParamsOutsideTheirRangeAreRefusedNamingTheField) {
  ParallelGeometryParams p;
  p.platform_radius_m = 50e-3;  // beyond the base radius
  try {
    p.validate();
    FAIL();
  } catch (const InvalidParams& e) {
    EXPECT_EQ(e.field(), "platform_radius_m");
  }
  p = {};
  p.stroke_m = 50e-3;  // would carry a carriage past the platform's joint
  EXPECT_THROW(ParallelKinematics{p}, InvalidParams);
}

}  // namespace parallel_kinematics_test
}  // namespace mc::motion
