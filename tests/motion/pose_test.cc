// Pose conventions of 6-DOF positioners (pose.h): SmarPod's R = Rz Ry Rx and PI's U -> V -> W about
// moving axes, each against rotations composed here from Eigen's angle-axis, converted into each
// other exactly; the pivot point's two modes; the IK of a pose about a pivot.
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "microcobot/core/error.h"
#include "microcobot/motion/parallel_kinematics.h"
#include "microcobot/motion/pose.h"

namespace mc::motion {
namespace pose_test {

constexpr double kDeg = M_PI / 180.0;

Eigen::Matrix3d about(const Eigen::Vector3d& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

TEST(PoseConventions, SmarPodRotationIsAboutFixedXThenYThenZ) {
  const double rx = 0.3, ry = -0.2, rz = 0.7;
  // Extrinsic: each rotation about the fixed axes, the later ones multiplying from the left.
  const Eigen::Matrix3d explicit_R = about(Eigen::Vector3d::UnitZ(), rz) *
                                     about(Eigen::Vector3d::UnitY(), ry) *
                                     about(Eigen::Vector3d::UnitX(), rx);
  EXPECT_LT((smarpod_rotation(rx, ry, rz) - explicit_R).cwiseAbs().maxCoeff(), 1e-15);
  // A quarter turn about z takes x to y.
  EXPECT_LT((smarpod_rotation(0, 0, M_PI / 2) * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(),
            1e-15);
}

TEST(PoseConventions, PiRotationIsUThenVThenWAboutTheMovingAxes) {
  const double u = 0.3, v = -0.2, w = 0.7;
  // Intrinsic: V about the y axis as U left it, W about the z axis as U and V left it.
  const Eigen::Matrix3d after_u = about(Eigen::Vector3d::UnitX(), u);
  const Eigen::Matrix3d after_v = about(after_u * Eigen::Vector3d::UnitY(), v) * after_u;
  const Eigen::Matrix3d after_w = about(after_v * Eigen::Vector3d::UnitZ(), w) * after_v;
  EXPECT_LT((pi_rotation(u, v, w) - after_w).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LT((pi_rotation(u, v, w) - rot_x(u) * rot_y(v) * rot_z(w)).cwiseAbs().maxCoeff(), 1e-15);
  // Not the SmarPod matrix of the same three numbers (the conventions differ off the axes).
  EXPECT_GT((pi_rotation(u, v, w) - smarpod_rotation(u, v, w)).cwiseAbs().maxCoeff(), 1e-2);
}

TEST(PoseConventions, AnglesRoundTripThroughTheirMatricesToRounding) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> a(-M_PI, M_PI), mid(-0.49 * M_PI, 0.49 * M_PI);
  for (int n = 0; n < 10000; ++n) {
    const Eigen::Vector3d s(a(rng), mid(rng), a(rng));
    EXPECT_LT((smarpod_angles(smarpod_rotation(s.x(), s.y(), s.z())) - s).cwiseAbs().maxCoeff(), 1e-13);
    const Eigen::Vector3d p(a(rng), mid(rng), a(rng));
    EXPECT_LT((pi_angles(pi_rotation(p.x(), p.y(), p.z())) - p).cwiseAbs().maxCoeff(), 1e-13);
  }
}

TEST(PoseConventions, SmarPodAndPiPosesOfOneTransformConvertIntoEachOther) {
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> t(-5e-3, 5e-3), a(-20 * kDeg, 20 * kDeg);
  const Eigen::Vector3d pivot(1e-3, -2e-3, 3e-3);
  for (int n = 0; n < 10000; ++n) {
    const SmarPodPose s{t(rng), t(rng), t(rng), a(rng), a(rng), a(rng)};
    const PlatformTransform T = to_transform(s, {pivot, PivotMode::kRelative});
    const PiPose p = to_pi(T, pivot);
    const PlatformTransform T2 = to_transform(p, pivot);
    EXPECT_LT((T2.R - T.R).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_LT((T2.d - T.d).cwiseAbs().maxCoeff(), 1e-17);  // a few ulp of 5 mm
    const SmarPodPose back = to_smarpod(T2, {pivot, PivotMode::kRelative});
    for (int j = 0; j < 6; ++j) EXPECT_NEAR(back.as_array()[j], s.as_array()[j], j < 3 ? 1e-17 : 1e-15);
    // Both translate in the fixed frame about a moving pivot: the same X Y Z as x y z.
    EXPECT_NEAR(p.X, s.x, 1e-17);
    EXPECT_NEAR(p.Z, s.z, 1e-17);
  }
}

TEST(PivotModes, RelativePivotTravelsWithThePlatformAndStaysOnItsPoint) {
  const Pivot pivot{{2e-3, 1e-3, -4e-3}, PivotMode::kRelative};
  const SmarPodPose pose{1e-3, -2e-3, 0.5e-3, 5 * kDeg, -3 * kDeg, 8 * kDeg};
  const PlatformTransform T = to_transform(pose, pivot);
  // The platform's point at the pivot ends at pivot + translation, whatever the rotation.
  EXPECT_LT((T.R * pivot.point_m + T.d - (pivot.point_m + Eigen::Vector3d(1e-3, -2e-3, 0.5e-3))).norm(),
            1e-17);
  // Turning alone about it leaves that point where it is.
  const PlatformTransform turn = to_transform(SmarPodPose{0, 0, 0, 0.1, 0.2, 0.3}, pivot);
  EXPECT_LT((turn.R * pivot.point_m + turn.d - pivot.point_m).norm(), 1e-17);
}

TEST(PivotModes, FixedPivotStaysInSpaceWhileThePlatformTranslates) {
  const Pivot pivot{{2e-3, 1e-3, -4e-3}, PivotMode::kFixed};
  const Eigen::Vector3d t(1e-3, -2e-3, 0.5e-3);
  const SmarPodPose a{t.x(), t.y(), t.z(), 5 * kDeg, -3 * kDeg, 8 * kDeg};
  const SmarPodPose b{t.x(), t.y(), t.z(), -7 * kDeg, 2 * kDeg, 1 * kDeg};
  // The platform point that the translation brought onto the pivot stays on it for any angles.
  const Eigen::Vector3d q = pivot.point_m - t;
  for (const auto& p : {a, b}) {
    const PlatformTransform T = to_transform(p, pivot);
    EXPECT_LT((T.R * q + T.d - pivot.point_m).norm(), 1e-17);
  }
  // The two modes differ once the platform is both translated and turned ...
  const Pivot relative{pivot.point_m, PivotMode::kRelative};
  EXPECT_GT((to_transform(a, pivot).d - to_transform(a, relative).d).norm(), 1e-5);
  // ... and agree without a translation.
  const SmarPodPose turn{0, 0, 0, 5 * kDeg, -3 * kDeg, 8 * kDeg};
  EXPECT_LT((to_transform(turn, pivot).d - to_transform(turn, relative).d).norm(), 1e-18);
}

TEST(PivotModes, EachModeRoundTripsItsPose) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> t(-5e-3, 5e-3), a(-20 * kDeg, 20 * kDeg);
  for (PivotMode mode : {PivotMode::kRelative, PivotMode::kFixed}) {
    for (int n = 0; n < 1000; ++n) {
      const Pivot pivot{{t(rng), t(rng), t(rng)}, mode};
      const SmarPodPose s{t(rng), t(rng), t(rng), a(rng), a(rng), a(rng)};
      const SmarPodPose back = to_smarpod(to_transform(s, pivot), pivot);
      for (int j = 0; j < 6; ++j) EXPECT_NEAR(back.as_array()[j], s.as_array()[j], 1e-15);
    }
  }
  EXPECT_EQ(parse_pivot_mode("fixed"), PivotMode::kFixed);
  EXPECT_EQ(to_string(PivotMode::kRelative), "relative");
  EXPECT_THROW(parse_pivot_mode("moving"), UsageError);
}

TEST(PivotModes, TurningAboutAPivotAboveThePlatformMovesTheLegsUnlikeTurningAboutItsCentre) {
  // A tilt about a point 10 mm above the top plate swings the plate sideways: the legs see a
  // translation that a tilt about the plate's centre does not have.
  const ParallelKinematics k;
  const Pivot above{{0, 0, 10e-3}, PivotMode::kRelative};
  const SmarPodPose tilt{0, 0, 0, 2 * kDeg, 0, 0};
  LegCoordinates q_centre, q_above, q_equivalent;
  ASSERT_TRUE(k.inverse(to_transform(tilt), q_centre));
  ASSERT_TRUE(k.inverse(to_transform(tilt, above), q_above));
  EXPECT_GT((q_above - q_centre).norm(), 1e-4);
  // The same tilt about the centre plus the pivot's swing d = (I - R) c gives the same legs.
  PlatformTransform T = to_transform(tilt);
  T.d = above.point_m - T.R * above.point_m;
  ASSERT_TRUE(k.inverse(T, q_equivalent));
  EXPECT_LT((q_equivalent - q_above).lpNorm<Eigen::Infinity>(), 1e-17);
}

}  // namespace pose_test
}  // namespace mc::motion
