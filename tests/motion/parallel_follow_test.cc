// The parallel positioner following a streamed pose (ParallelStage::follow): it comes to rest on
// the target within the pose control's accuracy, never faster than the limits, stops at the
// workspace's edge instead of leaving it, follows a target moving at a jog's speed, and is refused
// where a move, a fault or a NaN says so; the tick allocates nothing.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "control_fixture.h"
#include "microcobot/motion/parallel_stage.h"
#include "microcobot/motion/parallel_workspace.h"
#include "support/counting_allocator.h"

namespace mc::motion {
namespace parallel_follow_test {

constexpr double kDeg = std::numbers::pi / 180.0;

double angle_between(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

void settle(ParallelStage& stage) {
  const double t_end = stage.time_s() + 1.0;
  while (!stage.at_rest() && stage.time_s() < t_end) stage.tick();
  ASSERT_TRUE(stage.at_rest());
}

// The reference's largest speeds while it ran (translation, rotation) and whether it came to rest.
struct Followed {
  double v_max = 0.0, w_max = 0.0;
  bool still = false;
};

Followed follow_until_still(ParallelStage& stage, double timeout_s) {
  Followed f;
  const double h = stage.tick_s(), t_end = stage.time_s() + timeout_s;
  PlatformTransform last = stage.reference_pose();
  int still_ticks = 0;
  while (stage.time_s() < t_end && still_ticks < 50) {
    stage.tick();
    const PlatformTransform& r = stage.reference_pose();
    f.v_max = std::max(f.v_max, (r.d - last.d).norm() / h);
    f.w_max = std::max(f.w_max, angle_between(last.R, r.R) / h);
    still_ticks = stage.moving() ? 0 : still_ticks + 1;
    last = r;
  }
  f.still = still_ticks >= 50;
  return f;
}

TEST(ParallelFollow, RandomTargetsAreReachedWithinHalfAMicronAndTenMicroradiansNeverFasterThanTheLimits) {
  // A seeded random set (seed 7), nothing tuned on it: targets up to 0.2 mm and 1 deg a coordinate
  // from home, reachable.
  ParallelStage stage(test::model(), test::step_map());
  settle(stage);
  const PoseMoveLimits& lim = stage.params().move;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst_m = 0.0, worst_rad = 0.0, v_max = 0.0, w_max = 0.0;
  for (int n = 0; n < 6;) {
    const PlatformTransform target = to_transform(SmarPodPose{
        0.2e-3 * u(rng), 0.2e-3 * u(rng), 0.2e-3 * u(rng), kDeg * u(rng), kDeg * u(rng), kDeg * u(rng)});
    if (!check_pose(stage.kinematics(), target).ok()) continue;
    ++n;
    ASSERT_TRUE(stage.follow(target));
    const Followed f = follow_until_still(stage, 30.0);
    ASSERT_TRUE(f.still) << "target " << n << " not reached in 30 s";
    EXPECT_FALSE(stage.follow_blocked());
    for (int k = 0; k < 3000; ++k) stage.tick();  // 0.3 s of hold: the legs settle on the reference
    worst_m = std::max(worst_m, (stage.true_pose().d - target.d).norm());
    worst_rad = std::max(worst_rad, angle_between(target.R, stage.true_pose().R));
    v_max = std::max(v_max, f.v_max);
    w_max = std::max(w_max, f.w_max);
  }
  EXPECT_FALSE(stage.fault());
  EXPECT_LE(worst_m, 0.5e-6);
  EXPECT_LE(worst_rad, 10e-6);
  EXPECT_LE(v_max, lim.max_speed_m_s * (1 + 1e-9));
  EXPECT_LE(w_max, lim.max_angular_speed_rad_s * (1 + 1e-9));
  EXPECT_GT(v_max, 0.5 * lim.max_speed_m_s) << "the reference never came near its speed limit";
  std::printf(
      "6 random targets (seed 7): at rest worst %.4f um, %.3f urad; peak speeds %.1f um/s, %.3f deg/s\n",
      worst_m * 1e6, worst_rad * 1e6, v_max * 1e6, w_max / kDeg);
}

TEST(ParallelFollow, ATargetBeyondTheStrokeStopsTheReferenceAtTheWorkspacesEdge) {
  ParallelStage stage(test::model(), test::step_map());
  settle(stage);
  PoseMoveLimits fast = stage.params().move;
  fast.max_speed_m_s = 600e-6;  // the edge reached within seconds
  fast.max_acceleration_m_s2 = 10e-3;
  const PlatformTransform beyond = to_transform(SmarPodPose{20e-3, 0, 0, 0, 0, 0});
  ASSERT_FALSE(check_pose(stage.kinematics(), beyond).ok());
  ASSERT_TRUE(stage.follow(beyond, fast));
  const Followed f = follow_until_still(stage, 30.0);
  ASSERT_TRUE(f.still);
  EXPECT_TRUE(stage.follow_blocked());
  EXPECT_FALSE(stage.fault());
  // Stopped on the edge: reachable, its farthest leg the margin short of its stroke's end (to a
  // tick's travel).
  const PlatformTransform edge = stage.reference_pose();
  const ReachCheck at_edge = check_pose(stage.kinematics(), edge);
  EXPECT_TRUE(at_edge.ok());
  const double end = 0.5 * stage.kinematics().params().stroke_m - kFollowStrokeMargin_m;
  EXPECT_LE(at_edge.q.cwiseAbs().maxCoeff(), end);
  EXPECT_GT(at_edge.q.cwiseAbs().maxCoeff(), end - fast.max_speed_m_s * stage.tick_s());
  EXPECT_GT(edge.d.x(), 1e-3);
  for (int k = 0; k < 3000; ++k) stage.tick();
  EXPECT_LT((stage.true_pose().d - edge.d).norm(), 0.5e-6);  // and holds there
  // Back inside: it moves again.
  ASSERT_TRUE(stage.follow(PlatformTransform{}, fast));
  for (int k = 0; k < 100; ++k) stage.tick();
  EXPECT_FALSE(stage.follow_blocked());
  EXPECT_LT(stage.reference_pose().d.x(), edge.d.x());
}

TEST(ParallelFollow, ATargetMovingAtAJogsSpeedIsFollowedAtThatSpeedAndStopHoldsWhereItIs) {
  ParallelStage stage(test::model(), test::step_map());
  settle(stage);
  // A jog of 50 um/s along y and 0.5 deg/s about z: the target a tenth of a second ahead of the
  // reference, streamed every tick.
  const Eigen::Vector3d v(0, 50e-6, 0), w(0, 0, 0.5 * kDeg);
  PoseMoveLimits jog = stage.params().move;
  jog.max_speed_m_s = v.norm();
  jog.max_angular_speed_rad_s = w.norm();
  double t = 0.0;
  while (t < 2.0) {
    PlatformTransform target = stage.reference_pose();
    target.d += 0.1 * v;
    target.R = exp_so3(0.1 * w) * target.R;
    ASSERT_TRUE(stage.follow(target, jog));
    stage.tick();
    t += stage.tick_s();
  }
  // At the jog's speed once accelerated: about 2 s x 50 um/s less the ramp's 1.25 um.
  EXPECT_NEAR(stage.reference_pose().d.y(), 2.0 * 50e-6, 3e-6);
  EXPECT_NEAR(log_so3(stage.reference_pose().R).z(), 2.0 * 0.5 * kDeg, 0.05 * kDeg);
  EXPECT_LT(std::abs(stage.true_pose().d.y() - stage.reference_pose().d.y()), 2e-6) << "the legs lag";
  stage.stop();
  EXPECT_FALSE(stage.following());
  const PlatformTransform at_stop = stage.true_pose();
  for (int k = 0; k < 5000; ++k) stage.tick();
  EXPECT_LT((stage.true_pose().d - at_stop.d).norm(), 1e-6);
  EXPECT_TRUE(stage.at_rest());
}

TEST(ParallelFollow, RefusedDuringAMoveAfterAnEmergencyStopAndForANanAndAMoveIsRefusedWhileFollowing) {
  ParallelStage stage(test::model(), test::step_map());
  settle(stage);
  const PlatformTransform near = to_transform(SmarPodPose{50e-6, 0, 0, 0, 0, 0});
  PlatformTransform nan_target;
  nan_target.d.x() = std::nan("");
  EXPECT_FALSE(stage.follow(nan_target));
  EXPECT_FALSE(stage.following());
  stage.move_to(near);
  EXPECT_FALSE(stage.follow(PlatformTransform{}));  // a move runs
  stage.stop();
  ASSERT_TRUE(stage.follow(near));
  const PoseTrajectory back(stage.reference_pose(), PlatformTransform{}, stage.params().move);
  EXPECT_FALSE(stage.start_move(back));  // following
  stage.emergency_stop();
  EXPECT_FALSE(stage.following());
  EXPECT_FALSE(stage.follow(near));
  stage.rearm();
  EXPECT_TRUE(stage.follow(near));
}

TEST(ParallelFollow, TickNeverAllocatesWhileFollowingOrBlockedAtTheEdge) {
  ParallelStage stage(test::model(), test::step_map());
  settle(stage);
  PoseMoveLimits fast = stage.params().move;
  fast.max_speed_m_s = 800e-6;
  fast.max_acceleration_m_s2 = 20e-3;
  mc::test::AllocationGuard guard;
  ASSERT_TRUE(stage.follow(to_transform(SmarPodPose{0, 20e-3, 0, 0, 0, 0.1}), fast));
  for (int k = 0; k < 150000 && !stage.follow_blocked(); ++k) stage.tick();
  EXPECT_TRUE(stage.follow_blocked());
  for (int k = 0; k < 100; ++k) stage.tick();
  stage.stop();
  EXPECT_EQ(guard.allocations(), 0u);
}

}  // namespace parallel_follow_test
}  // namespace mc::motion
