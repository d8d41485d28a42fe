#include "microcobot/live/console_command.h"
#include "microcobot/live/console_task.h"

#include <gtest/gtest.h>

#include <array>
#include <string>

#include "microcobot/core/error.h"

namespace mc::live {
namespace {

std::string message_of(const std::string& payload, const ConsoleLimits& limits = {}) {
  try {
    parse_console_command(payload, limits);
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "accepted";
}

TEST(ConsoleCommand, ParsesTheOperatorsCommandAndClampsItToThePlatformsLimits) {
  ConsoleLimits limits;
  limits.max_speed_m_s = 1e-3;
  const auto c = parse_console_command(
      R"({"deadman": true, "velocity_m_s": [3e-3, 4e-3, 0], "goal_m": [1, -2e-3, 0.5e-3],)"
      R"( "goal_speed_m_s": 5, "gripper_opening_m": 1e-3})",
      limits);
  EXPECT_TRUE(c.deadman);
  EXPECT_NEAR(c.velocity_m_s[0], 0.6e-3, 1e-15);  // 5 mm/s asked, 1 mm/s given, same direction
  EXPECT_NEAR(c.velocity_m_s[1], 0.8e-3, 1e-15);
  EXPECT_TRUE(c.has_goal);
  EXPECT_DOUBLE_EQ(c.goal_m[0], limits.max_m[0]);
  EXPECT_DOUBLE_EQ(c.goal_m[1], -2e-3);
  EXPECT_DOUBLE_EQ(c.goal_speed_m_s, 1e-3);
  EXPECT_TRUE(c.has_gripper);
  EXPECT_DOUBLE_EQ(c.gripper_opening_m, limits.max_opening_m);
  const auto idle = parse_console_command("{}", limits);
  EXPECT_FALSE(idle.deadman);
  EXPECT_FALSE(idle.has_goal);
  EXPECT_FALSE(idle.has_gripper);
}

TEST(ConsoleCommand, RefusesBadCommandsWithOneLineNamingTheField) {
  EXPECT_EQ(message_of("not json"), "/console/command: payload: is not valid JSON");
  EXPECT_EQ(message_of("[1,2]"), "/console/command: payload: must be a JSON object");
  EXPECT_EQ(message_of(R"({"deadman": 1})"), "/console/command: deadman: must be true or false");
  EXPECT_EQ(message_of(R"({"velocity_m_s": [0, "a", 0]})"),
            "/console/command: velocity_m_s[1]: must be a number");
  EXPECT_EQ(message_of(R"({"velocity_m_s": [0, 0]})"),
            "/console/command: velocity_m_s: must be an array of 3 numbers");
  EXPECT_EQ(message_of(R"({"goal_m": [0, 0, 1e999]})"), "/console/command: payload: is not valid JSON");
  EXPECT_EQ(message_of(R"({"goal_speed_m_s": -1})"), "/console/command: goal_speed_m_s: must be > 0");
  EXPECT_NE(message_of(R"({"fly": true})").find("fly: is not a known key"), std::string::npos);
  // A key with a line break (found by the fuzzer) is named escaped: the message stays one line.
  const std::string broken = message_of(R"({"deadm\n": true})");
  EXPECT_NE(broken.find("deadm\\n: is not a known key"), std::string::npos) << broken;
  EXPECT_EQ(broken.find('\n'), std::string::npos) << broken;
  EXPECT_EQ(message_of(R"({"goal_m": [0, 0, 1e308]})"), "accepted");  // finite: clamped to the workspace
  EXPECT_EQ(message_of(R"({"gripper_shake": 1})"), "/console/command: gripper_shake: must be true or false");
}

// The gripper's release burst: a flag riding on the command, off unless sent.
TEST(ConsoleCommand, TheGrippersReleaseBurstIsAFlagThatIsOffUnlessSent) {
  const ConsoleLimits limits;
  const ConsoleCommand c =
      parse_console_command(R"({"deadman": true, "gripper_opening_m": 4e-4, "gripper_shake": true})", limits);
  EXPECT_TRUE(c.gripper_shake);
  EXPECT_TRUE(c.has_gripper);
  EXPECT_FALSE(
      parse_console_command(R"({"deadman": true, "gripper_opening_m": 4e-4})", limits).gripper_shake);
  EXPECT_FALSE(parse_console_command(R"({"gripper_shake": false})", limits).gripper_shake);
}

// The rotary axis under the gripper: its goal clamped to its travel, its rate to
// its speed; refused where there is none, and non-numbers refused naming the key.
TEST(ConsoleCommand, TheRotaryAxisCommandsAreClampedAndRefusedWithoutTheAxis) {
  ConsoleLimits limits;
  limits.min_theta_rad = -1.0, limits.max_theta_rad = 1.0, limits.max_theta_speed_rad_s = 0.16;
  const auto c =
      parse_console_command(R"({"deadman": true, "theta_goal_rad": 7, "theta_rate_rad_s": -3})", limits);
  EXPECT_TRUE(c.has_theta_goal);
  EXPECT_DOUBLE_EQ(c.theta_goal_rad, 1.0);
  EXPECT_DOUBLE_EQ(c.theta_rate_rad_s, -0.16);
  EXPECT_FALSE(parse_console_command("{}", limits).has_theta_goal);
  EXPECT_EQ(message_of(R"({"theta_goal_rad": 0.1})"),
            "/console/command: theta_goal_rad: there is no rotary axis");
  try {
    parse_console_command(R"({"theta_rate_rad_s": "fast"})", limits);
    ADD_FAILURE() << "accepted";
  } catch (const InvalidInput& e) {
    EXPECT_STREQ(e.what(), "/console/command: theta_rate_rad_s: must be a number");
  }
}

TEST(ConsoleCommand, APoseGoalIsSixFiniteNumbersAndRefusedWithoutTheParallelPositioner) {
  ConsoleLimits limits;
  limits.has_positioner = true;
  const auto c =
      parse_console_command(R"({"deadman": true, "pose_goal": [1e-4, 0, -2e-5, 0.01, 0, -0.02]})", limits);
  ASSERT_TRUE(c.has_pose_goal);
  EXPECT_EQ(c.pose_goal, (std::array<double, 6>{1e-4, 0, -2e-5, 0.01, 0, -0.02}));
  EXPECT_FALSE(parse_console_command(R"({"deadman": true})", limits).has_pose_goal);
  EXPECT_EQ(message_of(R"({"pose_goal": [0, 0, 0, 0, 0, 0]})"),
            "/console/command: pose_goal: there is no parallel positioner (positioner: parallel)");
  const auto refused = [&](const std::string& payload) { return message_of(payload, limits); };
  EXPECT_EQ(refused(R"({"pose_goal": [0, 0, 0]})"),
            "/console/command: pose_goal: must be an array of 6 numbers [x, y, z, rx, ry, rz] (m, rad)");
  EXPECT_EQ(refused(R"({"pose_goal": [0, 0, 0, 0, "a", 0]})"),
            "/console/command: pose_goal[4]: must be a number");
}

TEST(ConsoleCommand, APoseJogIsSixFiniteNumbersClampedToTheMoveSpeedsAndNotWithAGoal) {
  ConsoleLimits limits;
  limits.has_positioner = true;
  limits.pose_max_speed_m_s = 100e-6;
  limits.pose_max_angular_speed_rad_s = 0.01;
  const auto c =
      parse_console_command(R"({"deadman": true, "pose_jog": [3e-4, 4e-4, 0, 0, 0, -0.002]})", limits);
  ASSERT_TRUE(c.has_pose_jog);
  // 500 um/s asked: 100 um/s along the same direction; the rotation within its cap unchanged.
  EXPECT_NEAR(c.pose_jog[0], 60e-6, 1e-12);
  EXPECT_NEAR(c.pose_jog[1], 80e-6, 1e-12);
  EXPECT_EQ(c.pose_jog[5], -0.002);
  EXPECT_NEAR(parse_console_command(R"({"pose_jog": [0, 0, 0, 0.03, 0.04, 0]})", limits).pose_jog[4], 0.008,
              1e-12);
  EXPECT_EQ(message_of(R"({"pose_jog": [0, 0, 0, 0, 0, 0]})"),
            "/console/command: pose_jog: there is no parallel positioner (positioner: parallel)");
  const auto refused = [&](const std::string& payload) { return message_of(payload, limits); };
  EXPECT_EQ(
      refused(R"({"pose_jog": [0, 0, 0, 0, 0]})"),
      "/console/command: pose_jog: must be an array of 6 numbers [vx, vy, vz, wx, wy, wz] (m/s, rad/s)");
  EXPECT_EQ(refused(R"({"pose_jog": [0, 0, null, 0, 0, 0]})"),
            "/console/command: pose_jog[2]: must be a number");
  EXPECT_EQ(refused(R"({"pose_jog": [0, 0, 0, 0, 0, 0], "pose_goal": [0, 0, 0, 0, 0, 0]})"),
            "/console/command: pose_jog: cannot come with pose_goal (a jog or a goal, one at a time)");
}

TEST(ConsoleCommand, AGoalPixelMustLieInTheCamerasFrame) {
  ConsoleLimits limits;
  limits.max_goal_px = {639.0, 511.0};
  const auto c = parse_console_command(R"({"deadman": true, "goal_px": [320.25, 511]})", limits);
  EXPECT_TRUE(c.has_goal_px);
  EXPECT_FALSE(c.has_goal);
  EXPECT_DOUBLE_EQ(c.goal_px[0], 320.25);
  EXPECT_DOUBLE_EQ(c.goal_px[1], 511.0);
  auto refused = [&](const std::string& payload, const ConsoleLimits& l) {
    try {
      parse_console_command(payload, l);
    } catch (const InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(refused(R"({"goal_px": [640, 0]})", limits),
            "/console/command: goal_px[0]: must be within the frame [0, 639]");
  EXPECT_EQ(refused(R"({"goal_px": [0, -1]})", limits),
            "/console/command: goal_px[1]: must be within the frame [0, 511]");
  EXPECT_EQ(refused(R"({"goal_px": [1, 2, 3]})", limits),
            "/console/command: goal_px: must be an array of 2 numbers");
  EXPECT_EQ(refused(R"({"goal_px": [1, "x"]})", limits), "/console/command: goal_px[1]: must be a number");
  EXPECT_EQ(refused(R"({"goal_px": [1, 2]})", ConsoleLimits{}),
            "/console/command: goal_px[0]: there is no camera");
}

TEST(ConsoleCommand, ParsesActionsAndRefusesUnknownOnes) {
  EXPECT_EQ(parse_console_action(R"({"action": "estop"})"), ConsoleAction::kEstop);
  EXPECT_EQ(parse_console_action(R"({"action": "reset"})"), ConsoleAction::kReset);
  EXPECT_EQ(parse_console_action(R"({"action": "demo"})"), ConsoleAction::kDemo);
  EXPECT_EQ(parse_console_action(R"({"action": "vision_tare"})"), ConsoleAction::kVisionTare);
  // The supervised task's controls (serve --cell), in the loop's TaskAction order.
  EXPECT_EQ(parse_console_action(R"({"action": "task_start"})"), ConsoleAction::kTaskStart);
  EXPECT_EQ(parse_console_action(R"({"action": "task_take_over"})"), ConsoleAction::kTaskTakeOver);
  EXPECT_EQ(parse_console_action(R"({"action": "task_step_done"})"), ConsoleAction::kTaskStepDone);
  EXPECT_EQ(parse_console_action(R"({"action": "task_skip"})"), ConsoleAction::kTaskSkip);
  EXPECT_TRUE(is_task_action(ConsoleAction::kTaskSkip));
  EXPECT_FALSE(is_task_action(ConsoleAction::kRecordStop));
  EXPECT_EQ(task_action(ConsoleAction::kTaskStepDone), TaskAction::kStepDone);
  EXPECT_EQ(task_action_name(ConsoleAction::kTaskHandBack), "task_hand_back");
  EXPECT_THROW(parse_console_action(R"({"action": "self_destruct"})"), InvalidInput);
  EXPECT_THROW(parse_console_action(R"({"action": 3})"), InvalidInput);
  EXPECT_THROW(parse_console_action(R"({"action": "estop", "x": 1})"), InvalidInput);
}

TEST(ConsoleCommand, RecordStartMayChooseTheVideoAndABadOneIsRefusedNamingIt) {
  EXPECT_FALSE(parse_action_request(R"({"action": "record_start"})").video.has_value());
  const ActionRequest jpeg = parse_action_request(R"({"action": "record_start", "video": "jpeg"})");
  EXPECT_EQ(jpeg.action, ConsoleAction::kRecordStart);
  EXPECT_EQ(jpeg.video, RecordedVideo::kJpeg);
  EXPECT_EQ(parse_action_request(R"({"action": "record_start", "video": "h264"})").video,
            RecordedVideo::kH264);
  EXPECT_EQ(parse_action_request(R"({"action": "record_start", "video": "off"})").video, RecordedVideo::kOff);
  const auto refused_action = [](std::string_view text) {
    try {
      parse_action_request(text);
    } catch (const InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(refused_action(R"({"action": "record_start", "video": "mp4"})"),
            "/console/action: video: mp4 must be h264, jpeg or off");
  EXPECT_EQ(refused_action(R"({"action": "record_start", "video": 1})"),
            "/console/action: video: 1 must be h264, jpeg or off");
  // Only record_start takes a video.
  EXPECT_NE(refused_action(R"({"action": "estop", "video": "jpeg"})"), "accepted");
}

}  // namespace
}  // namespace mc::live
