// The simulated parallel positioner with its controller on a thread of its own
// (`parallel_positioner.controller: thread`): its moves reach their goal as on the loop, the
// platform's rules (deadman, e-stop, reset) hold through the commands' ring, a move sent is moving
// before the controller has seen it, a silent host stops a move, and the loop's side allocates
// nothing. The controller runs on the wall clock: each test waits for the event it expects, with a
// deadline far beyond it.

#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <numbers>
#include <thread>

#include "microcobot/core/error.h"
#include "microcobot/motion/pose.h"
#include "microcobot/platform/platform.h"
#include "support/counting_allocator.h"
#include "support/test_support.h"

namespace mc::platform {
namespace {

using motion::PlatformTransform;
using motion::SmarPodPose;
constexpr double kOneDegree = std::numbers::pi / 180.0;

PlatformConfig threaded() {
  PlatformConfig c;
  c.positioner = "parallel";
  c.parallel_positioner.controller = "thread";
  return c;
}

void console_deadman(Platform& p, bool deadman) {
  teleop::ConsoleInput in;
  in.active = in.fresh = true;
  in.deadman = deadman;
  in.goal_m = {p.config().stage.home_x_m, p.config().stage.home_y_m, p.config().stage.home_z_m};
  p.set_console_input(in);
}

const devices::SimulatedParallelPositioner& threaded_sim(const Platform& p) {
  return *p.simulation().positioner;
}

/// Ticks the platform's loop ten ticks at a time, a millisecond apart, until `done` (true) or
/// `timeout_s` of wall time (false).
template <class Done>
bool tick_until(Platform& p, Done done, double timeout_s = 60.0) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < end) {
    p.loop().run_for(10);
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return false;
}

motion::PoseTrajectory checked_move(const Platform& p, const SmarPodPose& goal) {
  motion::PoseTrajectory t(p.positioner()->reference_pose(), motion::to_transform(goal),
                           p.config().parallel_positioner.move);
  const motion::MoveCheck c = motion::check_move(p.positioner()->kinematics(), t);
  EXPECT_TRUE(c.ok) << c.reason;
  return t;
}

double gap_m(const PlatformTransform& a, const PlatformTransform& b) { return (a.d - b.d).norm(); }

TEST(PositionerControllerThread, APoseMoveReachesItsGoalAndIsMovingFromTheMomentItIsSent) {
  Platform p{threaded()};
  ASSERT_NE(threaded_sim(p).controller(), nullptr);
  ASSERT_TRUE(tick_until(p, [&] { return p.positioner()->at_rest(); }));  // the legs power up
  console_deadman(p, true);
  const SmarPodPose goal{30e-6, -20e-6, 10e-6, 0.05 * kOneDegree, 0.0, -0.1 * kOneDegree};
  ASSERT_TRUE(p.start_pose_move(checked_move(p, goal)));
  // Sent, not yet applied by the controller: already moving, not at rest (a script waiting for
  // the move's end must not see the rest from before it).
  EXPECT_TRUE(p.positioner()->moving());
  EXPECT_FALSE(p.positioner()->at_rest());
  ASSERT_TRUE(tick_until(p, [&] { return !p.positioner()->moving() && p.positioner()->at_rest(); }));
  EXPECT_EQ(threaded_sim(p).controller()->view().refused, 0u);
  // On target within a micron and a millidegree, measured and true.
  const PlatformTransform want = motion::to_transform(goal);
  EXPECT_LT(gap_m(p.positioner()->measured_pose(), want), 1e-6);
  EXPECT_LT(gap_m(threaded_sim(p).true_pose(), want), 1e-6);
  const Eigen::Vector3d rz = motion::smarpod_angles(threaded_sim(p).true_pose().R);
  EXPECT_NEAR(rz.z(), -0.1 * kOneDegree, 1e-3 * kOneDegree);
  EXPECT_GT(threaded_sim(p).controller()->view().periods, 0u);
}

TEST(PositionerControllerThread, TheDeadmanReleasedHoldsTheMoveWhereItIs) {
  Platform p{threaded()};
  ASSERT_TRUE(tick_until(p, [&] { return p.positioner()->at_rest(); }));
  console_deadman(p, true);
  ASSERT_TRUE(p.start_pose_move(checked_move(p, {0.2e-3, 0, 0, 0, 0, 0})));
  const PlatformTransform home = threaded_sim(p).true_pose();
  ASSERT_TRUE(tick_until(p, [&] { return gap_m(threaded_sim(p).true_pose(), home) > 10e-6; }));
  console_deadman(p, false);
  ASSERT_TRUE(tick_until(p, [&] { return !p.positioner()->moving() && p.positioner()->at_rest(); }));
  const PlatformTransform held = threaded_sim(p).true_pose();
  EXPECT_GT(gap_m(held, motion::to_transform(SmarPodPose{0.2e-3, 0, 0, 0, 0, 0})), 10e-6);  // stopped short
  // Held: 0.2 s later (two thousand of the controller's periods) it has not crept.
  const std::uint64_t periods = threaded_sim(p).controller()->view().periods;
  ASSERT_TRUE(tick_until(p, [&] { return threaded_sim(p).controller()->view().periods > periods + 2000; }));
  EXPECT_LT(gap_m(threaded_sim(p).true_pose(), held), 0.3e-6);
  // Without the deadman nothing starts.
  EXPECT_FALSE(p.start_pose_move(checked_move(p, {0.1e-3, 0, 0, 0, 0, 0})));
}

TEST(PositionerControllerThread, AnEstopPutsEveryLegAtZeroVoltsAndTheResetHoldsWhereItStopped) {
  Platform p{threaded()};
  ASSERT_TRUE(tick_until(p, [&] { return p.positioner()->at_rest(); }));
  console_deadman(p, true);
  ASSERT_TRUE(p.start_pose_move(checked_move(p, {0.2e-3, 0.1e-3, 0, 0, 0, 0.2 * kOneDegree})));
  ASSERT_TRUE(tick_until(p, [&] { return threaded_sim(p).controller()->view().moving; }));
  p.fault_all();
  EXPECT_EQ(p.positioner()->state(), devices::Lifecycle::kFault);
  ASSERT_TRUE(tick_until(p, [&] {
    const auto& v = threaded_sim(p).controller()->view();
    return v.halted && v.max_leg_voltage_V == 0.0;
  }));
  EXPECT_FALSE(p.positioner()->moving());
  EXPECT_FALSE(p.start_pose_move(checked_move(p, {0, 0, 0, 0, 0, 0})));
  // The reset (between two runs of the loop, as the live platform makes it): armed again, the
  // legs hold where they are measured, and a move starts from there.
  p.recover();
  EXPECT_EQ(p.positioner()->state(), devices::Lifecycle::kActive);
  ASSERT_TRUE(tick_until(
      p, [&] { return !threaded_sim(p).controller()->view().halted && p.positioner()->at_rest(); }));
  EXPECT_LT(gap_m(p.positioner()->reference_pose(), p.positioner()->measured_pose()), 1e-6);
  ASSERT_TRUE(p.start_pose_move(checked_move(p, {0, 0, 0, 0, 0, 0})));
  ASSERT_TRUE(tick_until(p, [&] { return !p.positioner()->moving() && p.positioner()->at_rest(); }));
  EXPECT_LT(gap_m(threaded_sim(p).true_pose(), PlatformTransform{}), 1e-6);
}

TEST(PositionerControllerThread, AHostThatFallsSilentHasItsMoveStopped) {
  PlatformConfig c = threaded();
  c.parallel_positioner.controller_thread.host_timeout_s = 0.02;
  Platform p{c};
  ASSERT_TRUE(tick_until(p, [&] { return p.positioner()->at_rest(); }));
  console_deadman(p, true);
  ASSERT_TRUE(p.start_pose_move(checked_move(p, {0.3e-3, 0, 0, 0, 0, 0})));
  ASSERT_TRUE(tick_until(p, [&] { return threaded_sim(p).controller()->view().moving; }));
  // The loop stops for 15 times the timeout: the controller stops the move on its own.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  p.loop().run_for(1);
  ASSERT_TRUE(tick_until(
      p, [&] { return threaded_sim(p).controller()->view().host_lost; }, 10.0));
  ASSERT_TRUE(tick_until(p, [&] { return !p.positioner()->moving() && p.positioner()->at_rest(); }));
  EXPECT_FALSE(p.faulted());  // holding, not a fault: the host may plan its next move from here
}

TEST(PositionerControllerThread, TheLoopsSideAllocatesNothing) {
  Platform p{threaded()};
  ASSERT_TRUE(tick_until(p, [&] { return p.positioner()->at_rest(); }));
  console_deadman(p, true);
  const motion::PoseTrajectory t = checked_move(p, {50e-6, 0, 0, 0, 0, 0.1 * kOneDegree});
  test::AllocationGuard guard(std::this_thread::get_id());
  ASSERT_TRUE(p.start_pose_move(t));
  p.loop().run_for(2000);
  p.hold();
  p.loop().run_for(100);
  EXPECT_EQ(guard.allocations(), 0u);
}

TEST(PositionerControllerThread, ABadControllerOrThreadParameterIsOneLineNamingIt) {
  test::TempDir dir;
  const struct {
    const char* yaml;
    const char* names;
  } cases[] = {{"parallel_positioner: {controller: fiber}\n", "'fiber'"},
               {"parallel_positioner: {controller_thread: {wake_period_s: 1.0}}\n", "wake_period_s"},
               {"parallel_positioner: {controller_thread: {host_timeout_s: 0}}\n", "host_timeout_s"}};
  for (const auto& k : cases) {
    std::ofstream(dir / "platform.yaml") << k.yaml;
    try {
      load_platform_config(dir / "platform.yaml");
      ADD_FAILURE() << "accepted " << k.yaml;
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(k.names), std::string::npos) << what;
      EXPECT_NE(what.find("parallel_positioner"), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

TEST(PositionerControllerThread, AStreamedTargetIsPursuedAsTheConsolesJogStreamsIt) {
  Platform p{threaded()};
  console_deadman(p, true);
  ASSERT_TRUE(tick_until(p, [&] { return p.positioner()->at_rest(); }));
  const Eigen::Vector3d start = threaded_sim(p).true_pose().d;
  // The jog's stream: every tick, a target a quarter of a second ahead of the reference at 50 um/s.
  motion::PoseMoveLimits limits = p.config().parallel_positioner.move;
  limits.max_speed_m_s = 50e-6;
  const auto moved = [&] { return (threaded_sim(p).true_pose().d - start).y(); };
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (moved() < 20e-6 && std::chrono::steady_clock::now() < end) {
    for (int i = 0; i < 10; ++i) {
      PlatformTransform target = p.positioner()->reference_pose();
      target.d.y() += 0.25 * 50e-6;
      p.follow_pose(target, limits);
      p.loop().run_for(1);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_GE(moved(), 20e-6) << "the plate followed the streamed target";
  EXPECT_TRUE(p.positioner()->following());
}

}  // namespace
}  // namespace mc::platform
