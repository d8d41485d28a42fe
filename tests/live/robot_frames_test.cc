#include "microcobot/live/robot_frames.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <string>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "microcobot/core/error.h"
#include "microcobot/motion/parallel_kinematics.h"
#include "support/counting_allocator.h"

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

platform::TelemetrySchema schema_with_positioner() {
  platform::TelemetrySchema schema = platform::builtin_telemetry(true);
  for (const char* n : {"positioner_x_m", "positioner_y_m", "positioner_z_m"}) schema.add({n, "m", "pose"});
  for (const char* n : {"positioner_rx_rad", "positioner_ry_rad", "positioner_rz_rad"})
    schema.add({n, "rad", "pose"});
  return schema;
}

/// A sample whose positioner channels hold (x, y, z, rx, ry, rz).
platform::TelemetrySample positioner_sample(const platform::TelemetrySchema& schema,
                                            const std::array<double, 6>& p) {
  platform::TelemetrySample s = sample(schema);
  const char* names[] = {"positioner_x_m",    "positioner_y_m",    "positioner_z_m",
                         "positioner_rx_rad", "positioner_ry_rad", "positioner_rz_rad"};
  for (std::size_t i = 0; i < 6; ++i) s[schema.index(names[i])] = p[i];
  return s;
}

const FrameTransform& find(const FrameTransforms& f, std::size_t n, std::string_view child) {
  for (std::size_t i = 0; i < n; ++i)
    if (f[i].child == child) return f[i];
  throw std::runtime_error("no frame " + std::string(child));
}

/// The transform's rigid motion: a point in `child` to `parent`.
Eigen::Isometry3d isometry(const FrameTransform& t) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.linear() = Eigen::Quaterniond(t.qw, t.qx, t.qy, t.qz).toRotationMatrix();
  m.translation() = Eigen::Vector3d(t.x_m, t.y_m, t.z_m);
  return m;
}

// Each leg's frame starts at its carriage's spherical joint B_i and its z axis runs the leg's
// length L to the platform's revolute joint P_i, both from the kinematics' closure at the measured
// pose; through the frame tree, that end is where the platform's own frame puts the joint
// (d + R p_i in {H}): the drawn legs hold the drawn platform at every pose.
TEST(RobotFrames, EachLegsFrameSpansFromItsCarriagesJointToThePlatformsJointAtTheMeasuredPose) {
  const platform::TelemetrySchema schema = schema_with_positioner();
  const motion::ParallelGeometryParams geometry;
  const RobotFrames frames(schema, &geometry);
  ASSERT_NE(frames.positioner_kinematics(), nullptr);
  const motion::ParallelKinematics kinematics(geometry);
  const double L = kinematics.geometry().leg_length_m;
  for (const std::array<double, 6>& p : {std::array<double, 6>{0, 0, 0, 0, 0, 0},
                                         std::array<double, 6>{1e-3, -0.5e-3, 0.8e-3, 0.05, -0.03, 0.1},
                                         std::array<double, 6>{-2e-3, 1.5e-3, -1e-3, -0.08, 0.06, -0.15}}) {
    motion::PlatformTransform T;
    T.R = motion::smarpod_rotation(p[3], p[4], p[5]);
    T.d = {p[0], p[1], p[2]};
    motion::LegClosure legs[motion::kParallelLegs];
    motion::LegCoordinates q;
    ASSERT_TRUE(kinematics.closures(T, legs, q));
    FrameTransforms f;
    const std::size_t n = frames.transforms(positioner_sample(schema, p), f);
    ASSERT_EQ(n, kMaxRobotFrames);
    const FrameTransform& base = find(f, n, "positioner_base");
    EXPECT_EQ(base.parent, "world");
    EXPECT_DOUBLE_EQ(base.z_m, -kinematics.geometry().home_height_m);
    const Eigen::Isometry3d world_base = isometry(base), world_platform = isometry(find(f, n, "positioner"));
    for (int i = 0; i < motion::kParallelLegs; ++i) {
      const std::string id = std::to_string(i);
      const FrameTransform& leg = find(f, n, "leg_" + id);
      EXPECT_EQ(leg.parent, "positioner_base");
      const Eigen::Isometry3d m = isometry(leg);
      EXPECT_LT((m.translation() - legs[i].carriage_m).norm(), 1e-15) << "leg " << i;
      EXPECT_LT((m * Eigen::Vector3d(0, 0, L) - legs[i].joint_m).norm(), 1e-12) << "leg " << i;
      const Eigen::Vector3d joint_in_world = world_platform * kinematics.geometry().legs[i].platform_m;
      EXPECT_LT((world_base * m * Eigen::Vector3d(0, 0, L) - joint_in_world).norm(), 1e-12) << "leg " << i;
      // The carriage at B_i = (b + u_i) e_r + w_i e_t, x along e_r: its coordinates are the legs'.
      const motion::LegGeometry& g = kinematics.geometry().legs[i];
      const FrameTransform& carriage = find(f, n, "carriage_" + id);
      const Eigen::Isometry3d c = isometry(carriage);
      const Eigen::Vector3d B = (geometry.base_radius_m + q[2 * i]) * g.e_r + q[2 * i + 1] * g.e_t;
      EXPECT_LT((c.translation() - B).norm(), 1e-15) << "carriage " << i;
      EXPECT_LT((c.linear() * Eigen::Vector3d::UnitX() - g.e_r).norm(), 1e-15) << "carriage " << i;
      EXPECT_LT((c.linear() * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitZ()).norm(), 1e-15);
    }
  }
}

TEST(RobotFrames, APoseNoLegsCloseAtSendsThePlatformAndItsBaseAloneAndTransformsNeverAllocate) {
  const platform::TelemetrySchema schema = schema_with_positioner();
  const motion::ParallelGeometryParams geometry;
  const RobotFrames frames(schema, &geometry);
  FrameTransforms f;
  // 30 mm up: beyond the legs' length (28.3 mm) above the carriages.
  EXPECT_EQ(frames.transforms(positioner_sample(schema, {0, 0, 30e-3, 0, 0, 0}), f), 7u);
  EXPECT_EQ(f[6].child, "positioner_base");
  EXPECT_EQ(frames.transforms(
                positioner_sample(schema, {std::numeric_limits<double>::quiet_NaN(), 0, 0, 0, 0, 0}), f),
            kMaxRobotFrames);  // NaN read as 0: home
  // Without the geometry (the DDS frames): the platform's frame alone.
  EXPECT_EQ(RobotFrames(schema).transforms(positioner_sample(schema, {}), f), 6u);
  const platform::TelemetrySample s = positioner_sample(schema, {1e-3, -0.5e-3, 0.8e-3, 0.05, -0.03, 0.1});
  std::size_t n = 0;
  test::AllocationGuard guard;
  for (int k = 0; k < 100; ++k) n += frames.transforms(s, f);
  EXPECT_EQ(guard.allocations(), 0u);
  EXPECT_EQ(n, 100 * kMaxRobotFrames);
}

// The positioner's bodies: its base plate, each carriage with its spherical joint, each leg a
// cylinder of the leg's length L from B_i to P_i along its frame's z, and the platform's plate
// under {P}'s origin with its revolute joints at p_i and the origin (the default pivot) marked.
TEST(RobotFrames, TheSceneDrawsThePositionersBaseCarriagesLegsAndPlatformInTheirFrames) {
  const platform::TelemetrySchema schema = schema_with_positioner();
  motion::ParallelGeometryParams geometry;
  geometry.joint_height_m = 25e-3;  // not the default: the bodies follow the geometry
  const RobotFrames frames(schema, &geometry);
  const motion::ParallelGeometry& g = frames.positioner_kinematics()->geometry();
  const json u = json::parse(frames.scene_update_json(RobotBodies{}, 2.0));
  std::map<std::string, json> by_id;
  for (const json& e : u["entities"]) {
    EXPECT_EQ(e["frame_id"], e["id"]);
    by_id[e["id"].get<std::string>()] = e;
  }
  ASSERT_EQ(by_id.size(), 2u + 2u * motion::kParallelLegs) << u.dump();
  for (int i = 0; i < motion::kParallelLegs; ++i) {
    const json& leg = by_id.at("leg_" + std::to_string(i))["cylinders"];
    ASSERT_EQ(leg.size(), 1u);
    EXPECT_DOUBLE_EQ(leg[0]["size"]["z"].get<double>(), g.leg_length_m);
    EXPECT_DOUBLE_EQ(leg[0]["pose"]["position"]["z"].get<double>(), 0.5 * g.leg_length_m);
    const json& carriage = by_id.at("carriage_" + std::to_string(i));
    ASSERT_EQ(carriage["spheres"].size(), 1u);
    EXPECT_EQ(carriage["spheres"][0]["pose"]["position"]["z"].get<double>(), 0.0);  // the joint: B_i
    EXPECT_LT(carriage["cubes"][0]["pose"]["position"]["z"].get<double>(), 0.0);    // under it
  }
  const json& platform = by_id.at("positioner");
  ASSERT_EQ(platform["cylinders"].size(), 1u + motion::kParallelLegs);  // the plate, the joints
  for (int i = 0; i < motion::kParallelLegs; ++i) {
    const json& c = platform["cylinders"][i + 1]["pose"]["position"];
    const Eigen::Vector3d at(c["x"].get<double>(), c["y"].get<double>(), c["z"].get<double>());
    EXPECT_LT((at - g.legs[i].platform_m).norm(), 1e-15) << "revolute joint " << i;
  }
  EXPECT_LE(platform["cylinders"][0]["pose"]["position"]["z"].get<double>(), 0.0);  // under the top
  ASSERT_EQ(platform["spheres"].size(), 1u);
  EXPECT_EQ(platform["spheres"][0]["pose"]["position"]["x"].get<double>(), 0.0);
  EXPECT_EQ(by_id.at("positioner_base")["cylinders"].size(), 1u);
  // Without the geometry, no positioner bodies.
  EXPECT_EQ(json::parse(RobotFrames(schema).scene_update_json(RobotBodies{}, 2.0))["entities"].size(), 0u);
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
