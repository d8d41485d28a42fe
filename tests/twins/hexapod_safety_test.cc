// The hexapod twin moves the platform's parallel positioner only under the platform's safety: a
// pose move is refused with its reason before anything moves; the console's e-stop stops a move
// (every leg at 0 V) and MOV?, ONT? and ERR? say so until the reset; a console user taking control
// without the deadman holds it, and so does the twin client's heartbeat gone stale.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <numbers>
#include <string>
#include <thread>

#include "hexapod_server_rig.h"
#include "microcobot/core/error.h"
#include "microcobot/motion/parallel_workspace.h"
#include "microcobot/motion/pose.h"
#include "support/live_status_wait.h"

namespace mc::twins {
namespace hexapod_safety_test {

using namespace std::chrono_literals;
using motion::PlatformTransform;
using motion::SmarPodPose;
using testing::axis;
using testing::byte_reply;
using testing::Client;
using testing::HexapodRig;
using testing::HexapodServerRig;
using testing::reference;
using testing::wait_on_target;

constexpr double kDeg = std::numbers::pi / 180.0;

TEST(HexapodSafety, APoseMoveIsRefusedWithItsReasonBeforeAnythingMoves) {
  HexapodRig r;
  std::this_thread::sleep_for(300ms);  // the legs' trackers power up
  const motion::ParallelKinematics& k = *r.stage.positioner_kinematics();
  const motion::PoseMoveLimits lim = r.stage.positioner_limits();
  // A pose for each reason: beyond a stroke, the legs vertical (singular), above them (out of
  // reach), and the first turn about a horizontal axis whose passive joints leave their limits.
  const double vertical = k.geometry().leg_length_m - k.params().joint_height_m;
  SmarPodPose joint{};
  for (double a = 1.0; a < 89.0; a += 0.5) {
    const SmarPodPose p{0, 0, 0, a * kDeg, 0, 0};
    if (motion::check_pose(k, p).reach == motion::Reach::kJointLimit) {
      joint = p;
      break;
    }
  }
  ASSERT_GT(joint.rx, 0.0) << "no joint-limited turn about x below 89 deg";
  const std::pair<SmarPodPose, const char*> cases[] = {{{9e-3, 0, 0, 0, 0, 0}, "stroke limit"},
                                                       {{0, 0, vertical - 1e-9, 0, 0, 0}, "singular"},
                                                       {{0, 0, vertical + 1e-6, 0, 0, 0}, "out of reach"},
                                                       {joint, "joint limit"}};
  const live::PositionerView before = r.stage.positioner_view();
  for (const auto& [goal, why] : cases) {
    const motion::PoseTrajectory traj(before.reference, motion::to_transform(goal), lim);
    std::uint64_t seq = 0;
    std::string reason;
    EXPECT_EQ(r.stage.move_pose(1, traj, seq, reason), TwinStage::Refusal::kUnreachable) << why;
    EXPECT_NE(reason.find(why), std::string::npos) << reason;
    EXPECT_EQ(reason.find('\n'), std::string::npos) << reason;
    EXPECT_EQ(seq, 0u) << "nothing was sent";
  }
  // A pose that is not a number never becomes a trajectory.
  PlatformTransform nan_goal;
  nan_goal.d.x() = std::nan("");
  EXPECT_THROW(motion::PoseTrajectory(before.reference, nan_goal, lim), InvalidInput);
  std::this_thread::sleep_for(200ms);
  const live::PositionerView after = r.stage.positioner_view();
  EXPECT_FALSE(after.moving);
  EXPECT_EQ(after.started_seq, before.started_seq);
  EXPECT_LT((after.measured.d - before.measured.d).norm(), 0.2e-6);
}

TEST(HexapodSafety, TheConsolesEstopStopsTheTwinsMoveAndMovOntErrSaySo) {
  HexapodServerRig rig;
  Client c(rig.port(), 5.0);
  reference(c);
  c.send("MOV X 0.2\n");  // 2 s at 0.1 mm/s
  ASSERT_EQ(c.gcs("ERR?"), "0\n");
  // The e-stop falls mid-move: once the twin says every axis moves and X is 20 um on its way
  // (waited for, not slept: instrumented by a sanitizer the move starts later).
  const auto until = std::chrono::steady_clock::now() + 10s;
  bool underway = false;
  while (!underway && std::chrono::steady_clock::now() < until) {
    underway = byte_reply(c, 5) == "3F\n" && axis(c, "POS? X") > 0.02;
    if (!underway) std::this_thread::sleep_for(20ms);
  }
  ASSERT_TRUE(underway) << "the move did not get under way";
  rig.live->estop();
  ASSERT_TRUE(test::wait_status(
      *rig.live, [](const live::LiveStatus& s) { return s.estopped; }, 2.0));
  std::this_thread::sleep_for(50ms);
  const double x = axis(c, "POS? X");
  EXPECT_GT(x, 0.01);
  EXPECT_LT(x, 0.19);  // short of the goal
  std::this_thread::sleep_for(300ms);
  EXPECT_NEAR(axis(c, "POS? X"), x, 0.5e-3);  // stopped, not moving on
  EXPECT_NEAR(axis(c, "MOV? X"), x, 1e-3);    // the target is where it stopped
  EXPECT_EQ(c.gcs("ONT? X"), "X=0\n");        // not on target: every leg at 0 V
  EXPECT_EQ(byte_reply(c, 5), "0\n");         // not moving
  EXPECT_EQ(c.gcs("ERR?"), "10\n");           // stopped
  // The telemetry's legs at 0 V: waited for, its samples reach the test through the platform's drain
  // thread, which a loaded machine under a sanitizer may leave behind by a second.
  const auto logged_until = std::chrono::steady_clock::now() + 5s;
  while (rig.u_max_V.load() != 0.0 && std::chrono::steady_clock::now() < logged_until)
    std::this_thread::sleep_for(10ms);
  EXPECT_DOUBLE_EQ(rig.u_max_V.load(), 0.0);
  c.send("MOV X 0\n");  // refused while the e-stop is latched
  EXPECT_EQ(c.gcs("ERR?"), "10\n");
  std::this_thread::sleep_for(200ms);
  EXPECT_NEAR(axis(c, "POS? X"), x, 0.5e-3);
  // The explicit reset: the legs hold where they stopped, and move again on the next command.
  rig.live->request(live::ConsoleAction::kReset);
  ASSERT_TRUE(test::wait_status(
      *rig.live, [](const live::LiveStatus& s) { return !s.estopped; }, 5.0));
  ASSERT_TRUE(wait_on_target(c, 5.0));
  EXPECT_NEAR(axis(c, "MOV? X"), axis(c, "POS? X"), 1e-3);
  c.send("MOV X 0\n");
  EXPECT_EQ(c.gcs("ERR?"), "0\n");
  ASSERT_TRUE(wait_on_target(c));
  EXPECT_NEAR(axis(c, "POS? X"), 0.0, 1e-3);
}

TEST(HexapodSafety, AConsoleUserInControlWithoutTheDeadmanHoldsTheTwinsMoveAndRefusesItsNext) {
  HexapodServerRig rig;
  Client c(rig.port(), 5.0);
  reference(c);
  c.send("MOV X 0.2\n");
  ASSERT_EQ(c.gcs("ERR?"), "0\n");
  std::this_thread::sleep_for(400ms);
  rig.live->set_console_in_control(true);  // takes control and sends nothing: no deadman
  std::this_thread::sleep_for(50ms);
  const double x = axis(c, "POS? X");
  EXPECT_GT(x, 0.005);
  EXPECT_LT(x, 0.15);
  std::this_thread::sleep_for(300ms);
  EXPECT_NEAR(axis(c, "POS? X"), x, 0.5e-3);  // holds
  EXPECT_EQ(byte_reply(c, 5), "0\n");
  EXPECT_NEAR(axis(c, "MOV? X"), x, 1e-3);  // the target is where it holds
  c.send("MOV X 0\n");
  EXPECT_EQ(c.gcs("ERR?"), "10\n");  // another operator holds the platform
  std::this_thread::sleep_for(300ms);
  EXPECT_NEAR(axis(c, "POS? X"), x, 0.5e-3);
  // Handed back: the twin takes control with its next motion command.
  rig.live->set_console_in_control(false);
  c.send("MOV X 0\n");
  EXPECT_EQ(c.gcs("ERR?"), "0\n");
  ASSERT_TRUE(wait_on_target(c));
  EXPECT_NEAR(axis(c, "POS? X"), 0.0, 1e-3);
}

TEST(HexapodSafety, ATwinMoveHoldsWhenItsClientsHeartbeatGoesStale) {
  HexapodRig r(/*start=*/true, /*command_timeout_s=*/0.2);
  r.reference();
  // Sent, then no heartbeat: after 0.2 s the protocol's input is stale and the platform holds.
  ASSERT_EQ(r.twin.on_line(1, "MOV X 0.2"), "");
  ASSERT_EQ(r.twin.on_line(1, "ERR?"), "0\n");
  std::this_thread::sleep_for(700ms);
  const live::PositionerView v = r.stage.positioner_view();
  EXPECT_FALSE(v.moving);
  const double x_mm = v.measured.d.x() * 1e3;
  EXPECT_GT(x_mm, 0.005);
  EXPECT_LT(x_mm, 0.05);  // 0.07 mm had it run on for the 0.7 s
  std::this_thread::sleep_for(300ms);
  EXPECT_NEAR(r.stage.positioner_view().measured.d.x() * 1e3, x_mm, 0.5e-3);
  // The client is told, as after a stop: the target is where the legs hold and the error is 10,
  // never an on-target at a goal it did not reach.
  EXPECT_EQ(r.twin.on_line(1, "ERR?"), "10\n");
  const double target_mm = drivers::gcs2::parse_axis_values(r.twin.on_line(1, "MOV? X")).at(0).second;
  EXPECT_NEAR(target_mm, x_mm, 1e-3);
  EXPECT_EQ(r.twin.on_line(1, "FRF? X"), "X=1\n");  // still referenced
}

}  // namespace hexapod_safety_test
}  // namespace mc::twins
