#include "microcobot/live/robot_frames.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "microcobot/core/error.h"

namespace mc::live {
namespace {

using nlohmann::json;

const json& frame(const json& tf, const std::string& child) {
  for (const json& t : tf["transforms"])
    if (t["child_frame_id"] == child) return t;
  throw std::runtime_error("no frame " + child);
}

platform::TelemetrySample sample(const platform::TelemetrySchema& schema) {
  platform::TelemetrySample s{};
  s[0] = 12.25;  // loop time
  s[schema.index("measured_x_m")] = 1e-3;
  s[schema.index("measured_y_m")] = -2e-3;
  s[schema.index("measured_z_m")] = 0.5e-3;
  s[schema.index("measured_theta_rad")] = std::numbers::pi / 2;
  s[schema.index("gripper_opening_m")] = 300e-6;
  return s;
}

TEST(RobotFrames, TheToolGripperAndFingersFollowTheMeasuredStageRotationAndOpening) {
  const platform::TelemetrySchema& schema = platform::builtin_telemetry(false);
  const RobotFrames frames(schema);
  EXPECT_FALSE(frames.has_part());  // a platform on hardware has no ground truth
  std::string out;
  frames.transforms_json(sample(schema), out);
  const json tf = json::parse(out);
  ASSERT_EQ(tf["transforms"].size(), 4u);
  const json& tool = frame(tf, "tool");
  EXPECT_EQ(tool["parent_frame_id"], "world");
  EXPECT_DOUBLE_EQ(tool["translation"]["x"].get<double>(), 1e-3);
  EXPECT_DOUBLE_EQ(tool["translation"]["y"].get<double>(), -2e-3);
  EXPECT_DOUBLE_EQ(tool["translation"]["z"].get<double>(), 0.5e-3);
  EXPECT_EQ(tool["timestamp"]["sec"], 12);
  EXPECT_EQ(tool["timestamp"]["nsec"], 250000000);
  // A quarter turn about z: q = (0, 0, sin(pi/4), cos(pi/4)).
  const json& q = frame(tf, "gripper")["rotation"];
  EXPECT_NEAR(q["z"].get<double>(), std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(q["w"].get<double>(), std::sqrt(0.5), 1e-15);
  EXPECT_EQ(q["x"].get<double>(), 0.0);
  // The fingers +-opening/2 along the gripper's y.
  EXPECT_DOUBLE_EQ(frame(tf, "finger_left")["translation"]["y"].get<double>(), 150e-6);
  EXPECT_DOUBLE_EQ(frame(tf, "finger_right")["translation"]["y"].get<double>(), -150e-6);
  EXPECT_EQ(frame(tf, "finger_left")["parent_frame_id"], "gripper");
}

TEST(RobotFrames, ASimulatedPlatformAddsThePartAndAViewerNeverGetsNaN) {
  const platform::TelemetrySchema& schema = platform::builtin_telemetry(true);
  const RobotFrames frames(schema);
  ASSERT_TRUE(frames.has_part());
  platform::TelemetrySample s = sample(schema);
  s[schema.index("part_x_m")] = 3e-3;
  s[schema.index("part_yaw_rad")] = std::numbers::pi;
  s[schema.index("measured_y_m")] = std::numeric_limits<double>::quiet_NaN();
  s[schema.index("gripper_opening_m")] = std::numeric_limits<double>::infinity();
  std::string out;
  frames.transforms_json(s, out);
  EXPECT_EQ(out.find("null"), std::string::npos) << out;  // nlohmann writes NaN as null
  const json tf = json::parse(out);
  const json& part = frame(tf, "part");
  EXPECT_EQ(part["parent_frame_id"], "world");
  EXPECT_DOUBLE_EQ(part["translation"]["x"].get<double>(), 3e-3);
  EXPECT_NEAR(part["rotation"]["z"].get<double>(), 1.0, 1e-15);  // half a turn
  EXPECT_EQ(frame(tf, "tool")["translation"]["y"].get<double>(), 0.0);
  EXPECT_EQ(frame(tf, "finger_left")["translation"]["y"].get<double>(), 0.0);
}

TEST(RobotFrames, TheSceneDrawsTheFingersAndThePartAsBoxesOfTheirSizeInTheirFrames) {
  const RobotFrames frames(platform::builtin_telemetry(true));
  RobotBodies b;
  b.part_side_m = 200e-6;
  b.part_height_m = 100e-6;
  b.finger_width_m = 80e-6;
  b.finger_length_m = 2e-3;
  const json u = json::parse(frames.scene_update_json(b, 1.5));
  ASSERT_EQ(u["entities"].size(), 3u);
  for (const json& e : u["entities"]) {
    EXPECT_EQ(e["frame_id"], e["id"]);
    EXPECT_EQ(e["lifetime"]["sec"], 0);  // kept until replaced
    ASSERT_EQ(e["cubes"].size(), 1u);
  }
  const json& part = u["entities"][2]["cubes"][0];
  EXPECT_DOUBLE_EQ(part["size"]["x"].get<double>(), 200e-6);
  EXPECT_DOUBLE_EQ(part["size"]["z"].get<double>(), 100e-6);
  EXPECT_DOUBLE_EQ(part["pose"]["position"]["z"].get<double>(), 50e-6);  // standing on its base
  const json& finger = u["entities"][0]["cubes"][0];
  EXPECT_DOUBLE_EQ(finger["pose"]["position"]["z"].get<double>(), -1e-3);  // hanging from the tool point
  // Without a part (the optical trap's scene) nothing is drawn for it.
  b.part_side_m = 0.0;
  EXPECT_EQ(json::parse(frames.scene_update_json(b, 1.5))["entities"].size(), 2u);
}

// The positioner's pose, R = Rz(rz) Ry(ry) Rx(rx), as the quaternion qz qy qx: the same rotation
// as Eigen's product of the three elementary turns, on any angles.
TEST(RobotFrames, TheParallelPositionersPoseIsItsZyxRotationAsAQuaternion) {
  platform::TelemetrySchema schema = platform::builtin_telemetry(true);
  for (const char* n : {"positioner_x_m", "positioner_y_m", "positioner_z_m"}) schema.add({n, "m", "pose"});
  for (const char* n : {"positioner_rx_rad", "positioner_ry_rad", "positioner_rz_rad"})
    schema.add({n, "rad", "pose"});
  const RobotFrames frames(schema);
  ASSERT_TRUE(frames.has_positioner());
  for (const auto& [rx, ry, rz] :
       {std::array{0.1, -0.2, 0.3}, std::array{-0.26, 0.17, 2.5}, std::array{0.0, 0.0, 0.0}}) {
    platform::TelemetrySample s = sample(schema);
    s[schema.index("positioner_x_m")] = 1e-3;
    s[schema.index("positioner_rx_rad")] = rx;
    s[schema.index("positioner_ry_rad")] = ry;
    s[schema.index("positioner_rz_rad")] = rz;
    FrameTransforms f;
    const std::size_t n = frames.transforms(s, f);
    ASSERT_EQ(n, 6u);
    EXPECT_EQ(f[5].child, "positioner");
    EXPECT_EQ(f[5].x_m, 1e-3);
    const Eigen::Matrix3d R =
        (Eigen::AngleAxisd(rz, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(ry, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(rx, Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
    const Eigen::Quaterniond q(f[5].qw, f[5].qx, f[5].qy, f[5].qz);
    EXPECT_NEAR(q.norm(), 1.0, 1e-15);
    EXPECT_LT((q.toRotationMatrix() - R).norm(), 1e-14) << rx << " " << ry << " " << rz;
  }
}

TEST(RobotFrames, ASchemaWithoutTheStagesChannelsIsRefusedNamingTheChannel) {
  platform::TelemetrySchema bare;
  bare.add({"t_s", "s", "time"});
  try {
    RobotFrames frames(bare);
    FAIL() << "accepted a schema without the stage's channels";
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("measured_x_m"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mc::live
