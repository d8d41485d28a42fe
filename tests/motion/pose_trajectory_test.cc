// The straight line in pose space and its time profile: the tool point on the segment, the
// rotation on the geodesic at the same s, the trapezoid within its limits, and the refusal of a
// line that leaves the workspace between two reachable poses.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "microcobot/motion/pose_trajectory.h"

namespace mc::motion {
namespace pose_trajectory_test {

constexpr double kDeg = std::numbers::pi / 180.0;

TEST(PoseTrajectory, ToolPointStaysOnTheSegmentAndTheRotationGrowsInProportion) {
  PoseMoveLimits lim;
  lim.tool_z_m = 5e-3;  // a tool point 5 mm above the top plate
  const PlatformTransform a = to_transform(SmarPodPose{1e-3, -0.5e-3, 0.2e-3, 2 * kDeg, -1 * kDeg, 3 * kDeg});
  const PlatformTransform b =
      to_transform(SmarPodPose{-0.5e-3, 1e-3, -0.3e-3, -1 * kDeg, 2 * kDeg, -2 * kDeg});
  const PoseTrajectory t(a, b, lim);
  const Eigen::Vector3d c = lim.tool_m();
  const Eigen::Vector3d x0 = a.R * c + a.d, x1 = b.R * c + b.d;
  for (double s : {0.0, 0.1, 0.37, 0.5, 0.81, 1.0}) {
    const PlatformTransform T = t.at(s);
    const Eigen::Vector3d x = T.R * c + T.d;
    EXPECT_LT((x - (x0 + s * (x1 - x0))).norm(), 1e-15) << s;
    EXPECT_NEAR(Eigen::AngleAxisd(a.R.transpose() * T.R).angle(), s * t.angle_rad(), 1e-12) << s;
    EXPECT_NEAR(Eigen::AngleAxisd(T.R.transpose() * b.R).angle(), (1 - s) * t.angle_rad(), 1e-12) << s;
    const PathDeviation d = t.deviation(T);
    EXPECT_LT(d.position_m, 1e-15);
    EXPECT_LT(d.rotation_rad, 1e-9);
  }
  EXPECT_LT((t.at(1.0).d - b.d).norm(), 1e-15);
  EXPECT_LT((t.at(1.0).R - b.R).norm(), 1e-14);
}

TEST(PoseTrajectory, TrapezoidKeepsSpeedAndAccelerationOfBothHalvesWithinLimits) {
  const PoseMoveLimits lim;
  for (const auto& goal :
       {SmarPodPose{1e-3, 0, 0, 0, 0, 0}, SmarPodPose{0, 0, 0, 0, 0, 5 * kDeg},
        SmarPodPose{0.6e-3, 0.8e-3, 0, 3 * kDeg, 4 * kDeg, 0}, SmarPodPose{2e-6, 0, 0, 0, 0, 0}}) {
    const PoseTrajectory t(PlatformTransform{}, to_transform(goal), lim);
    double s_prev = 0.0, v_max = 0.0, a_max = 0.0, sd_prev = 0.0;
    const double dt = 1e-4;
    for (double time = dt; time <= t.duration_s() + dt; time += dt) {
      double s = 0, sd = 0, sdd = 0;
      t.profile(time, s, sd, sdd);
      EXPECT_GE(s, s_prev - 1e-15);  // monotone
      v_max = std::max(v_max, sd);
      a_max = std::max(a_max, std::abs(sd - sd_prev) / dt);
      s_prev = s;
      sd_prev = sd;
    }
    EXPECT_EQ(s_prev, 1.0);
    EXPECT_LE(v_max * t.length_m(), lim.max_speed_m_s * (1 + 1e-12));
    EXPECT_LE(v_max * t.angle_rad(), lim.max_angular_speed_rad_s * (1 + 1e-12));
    EXPECT_LE(a_max * t.length_m(), lim.max_acceleration_m_s2 * (1 + 1e-9));
    EXPECT_LE(a_max * t.angle_rad(), lim.max_angular_acceleration_rad_s2 * (1 + 1e-9));
  }
}

TEST(PoseTrajectory, ALineThatLeavesTheWorkspaceBetweenReachablePosesIsRefusedAlongIt) {
  // Seeded pairs of reachable poses across the whole workspace until one's line leaves it.
  const ParallelKinematics k;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> t(-5e-3, 5e-3), a(-10 * kDeg, 10 * kDeg);
  int found = 0;
  int pairs = 0;
  for (int n = 0; n < 200000 && found == 0; ++n) {
    const PlatformTransform p = to_transform(SmarPodPose{t(rng), t(rng), t(rng), a(rng), a(rng), a(rng)});
    const PlatformTransform q = to_transform(SmarPodPose{t(rng), t(rng), t(rng), a(rng), a(rng), a(rng)});
    if (!check_pose(k, p).ok() || !check_pose(k, q).ok()) continue;
    ++pairs;
    PoseMoveLimits lim;
    lim.max_leg_speed_m_s = 1.0;  // the reach only
    const MoveCheck c = check_move(k, PoseTrajectory(p, q, lim));
    if (c.ok) continue;
    ++found;
    EXPECT_EQ(c.reason.rfind("along the line at s = ", 0), 0u) << c.reason;
    EXPECT_NE(c.reason.find("unreachable"), std::string::npos) << c.reason;
    EXPECT_NE(c.reach, Reach::kReachable);
    std::printf("pair %d: %s\n", pairs, c.reason.c_str());
  }
  EXPECT_EQ(found, 1) << pairs << " pairs";
}

}  // namespace pose_trajectory_test
}  // namespace mc::motion
