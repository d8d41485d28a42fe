// The assembly cell's camera (cell_camera.h) on rendered frames, against the simulation's truth:
// the pin found in its slot (position and yaw the slot's play changed), its offset in the fingers
// seen between them, and a placed pin told apart from one on the rim or gone.
#include "microcobot/cell/cell_camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "cell/cell_test_support.h"
#include "microcobot/cell/assembly_batch.h"
#include "microcobot/core/error.h"

namespace mc::cell {
namespace {

using test::default_platform;

// Jobs of a batch seeded apart from the cell's tuning seeds (5, 2031, 3907, 28).
std::vector<AssemblyJob> jobs(int n, int seed = 61) {
  AssemblyBatchParams p;
  p.parts = n;
  p.seed = seed;
  return assembly_jobs(p);
}

platform::PlatformConfig config_of(const AssemblyJob& j) {
  platform::PlatformConfig c = default_platform();
  c.microworld = "pick-place";
  c.world = j.world;
  return c;
}

CellCameraParams on() {
  CellCameraParams p;
  p.enabled = true;
  return p;
}

// The tool far from the pin (its start at the stage's home), the gripper open.
platform::CameraScenePose in_slot(const AssemblyJob& j) {
  platform::CameraScenePose pose = platform::initial_pose(config_of(j));
  pose.tool_z_m = j.world.height_m() + 150e-6;
  return pose;
}

TEST(CellCamera, FindsThePinInItsSlotWhereThePlayPutIt) {
  for (const AssemblyJob& j : jobs(4)) {
    CellCamera camera(on(), config_of(j), static_cast<std::uint64_t>(j.index));
    const PinModel pin{j.side_m, j.world.height_m()};
    const PinSighting s = camera.look_slot(in_slot(j), pin, j.nominal_part_m, j.nominal_part_yaw_rad);
    ASSERT_TRUE(s.found) << s.reason;
    const Eigen::Vector2d truth = j.world.part_start_m.head<2>();
    // The play moved it by micrometres; the camera sees it to a tenth of a micrometre (a tenth of a pixel).
    EXPECT_GT((j.nominal_part_m - truth).norm(), 0.3e-6);
    EXPECT_LT((s.part_m.head<2>() - truth).norm(), 0.1e-6) << "part " << j.index;
    std::printf("slot look, part %d: %.1f nm off, yaw %.4f deg off\n", j.index,
                1e9 * (s.part_m.head<2>() - truth).norm(), (s.yaw_rad - j.world.part_yaw_rad) * 180 / M_PI);
    EXPECT_NEAR(s.yaw_rad, j.world.part_yaw_rad, 0.2 * M_PI / 180) << "part " << j.index;
  }
}

// The bore look (AssemblyBatchParams::bore_error_m): the bore found where the plate's errors put
// it, tens of micrometres from its drawing, to a fraction of a micrometre; a flat seat has none.
TEST(CellCamera, FindsTheBoreWhereThePlatesErrorsPutIt) {
  AssemblyBatchParams b;
  b.parts = 4;
  b.seed = 67;
  b.bore_error_m = 15e-6;
  for (const AssemblyJob& j : assembly_jobs(b)) {
    CellCamera camera(on(), config_of(j), static_cast<std::uint64_t>(j.index));
    // The pin still in its slot, the fingers at the home: the bore's station is clear.
    const PinSighting s = camera.look_bore(in_slot(j), j.target_m, j.target_yaw_rad);
    ASSERT_TRUE(s.found) << s.reason;
    const Eigen::Vector2d truth = j.world.target_m.head<2>();
    EXPECT_GT((j.target_m - truth).norm(), 3e-6) << "part " << j.index << ": the drawing is off";
    std::printf("bore look, part %d: the drawing %.1f um off, the look %.0f nm off\n", j.index,
                1e6 * (j.target_m - truth).norm(), 1e9 * (s.part_m.head<2>() - truth).norm());
    EXPECT_LT((s.part_m.head<2>() - truth).norm(), 0.3e-6) << "part " << j.index;
  }
  b.flat_fraction = 1.0;
  const AssemblyJob flat = assembly_jobs(b).front();
  CellCamera camera(on(), config_of(flat));
  EXPECT_FALSE(camera.look_bore(in_slot(flat), flat.target_m, flat.target_yaw_rad).found);
}

TEST(CellCamera, MeasuresThePinsOffsetAlongTheFingersBetweenThem) {
  for (const AssemblyJob& j : jobs(3, 62)) {
    const platform::PlatformConfig c = config_of(j);
    // Held over its bore 150 um up, the fingers turned to the bore, the pin 6 um along their y
    // (the slot's play the squeeze left) and centred across them.
    const double yaw = j.target_yaw_rad, grasp_z = j.world.hole_depth_m + 100e-6, lift = 150e-6;
    const Eigen::Vector2d ey(-std::sin(yaw), std::cos(yaw));
    platform::CameraScenePose pose;
    pose.tool_x_m = j.target_m.x(), pose.tool_y_m = j.target_m.y(), pose.tool_z_m = grasp_z + lift;
    pose.tool_yaw_rad = yaw;
    pose.opening_m = j.side_m;
    const Eigen::Vector2d part = j.target_m + 6e-6 * ey;
    pose.part_x_m = part.x(), pose.part_y_m = part.y(), pose.part_z_m = lift + 0.5 * j.world.height_m();
    pose.part_yaw_rad = yaw;
    CellCamera camera(on(), c, 7);
    const PinModel pin{j.side_m, j.world.height_m()};
    const Eigen::Vector3d tool(pose.tool_x_m, pose.tool_y_m, pose.tool_z_m);
    const PinSighting s = camera.look_held(pose, pin, tool, yaw, lift + j.world.height_m());
    ASSERT_TRUE(s.found) << s.reason;
    EXPECT_NEAR((s.part_m.head<2>() - j.target_m).dot(ey), 6e-6, 0.3e-6) << "part " << j.index;
    std::printf("held look, part %d: %.1f nm off\n", j.index,
                1e9 * ((s.part_m.head<2>() - j.target_m).dot(ey) - 6e-6));
  }
}

// The visual servo's look (look_align): the pin in the fingers and its bore seen from one camera
// pose. The view is off by micrometres (view_error_m), so each look alone is off by as much, but
// the servo's error, pin minus bore, is not: the same error moved both.
TEST(CellCamera, TheServoSeesThePinAgainstItsBoreWhereverTheViewIs) {
  AssemblyBatchParams b;
  b.parts = 3;
  b.seed = 64;
  b.bore_error_m = 10e-6;
  CellCameraParams p = on();
  p.view_error_m = 10e-6;
  for (const AssemblyJob& j : assembly_jobs(b)) {
    const platform::PlatformConfig c = config_of(j);
    CellCamera camera(p, c, static_cast<std::uint64_t>(j.index));
    const PinSighting bore = camera.look_bore(in_slot(j), j.target_m, j.target_yaw_rad);
    ASSERT_TRUE(bore.found) << bore.reason;
    const Eigen::Vector2d bore_truth = j.world.target_m.head<2>();
    const double view_off = (bore.part_m.head<2>() - bore_truth).norm();
    EXPECT_NEAR(view_off, camera.view_error().norm(), 0.3e-6) << "part " << j.index;
    // Held 150 um over the bore, the pin off its axis by (4, -7) um, 6 um along the fingers' y.
    const double yaw = j.target_yaw_rad, grasp_z = j.world.hole_depth_m + 100e-6, lift = 150e-6;
    const Eigen::Vector2d ey(-std::sin(yaw), std::cos(yaw));
    const Eigen::Vector2d part = bore_truth + Eigen::Vector2d(4e-6, -7e-6);
    const Eigen::Vector2d tool = part - 6e-6 * ey;
    platform::CameraScenePose pose;
    pose.tool_x_m = tool.x(), pose.tool_y_m = tool.y(), pose.tool_z_m = grasp_z + lift;
    pose.tool_yaw_rad = yaw;
    pose.opening_m = j.side_m;
    pose.part_x_m = part.x(), pose.part_y_m = part.y(), pose.part_z_m = lift + 0.5 * j.world.height_m();
    pose.part_yaw_rad = yaw;
    const PinModel pin{j.side_m, j.world.height_m()};
    const Eigen::Vector3d tool_m(tool.x(), tool.y(), pose.tool_z_m);
    const PinSighting s = camera.look_align(pose, pin, j.target_m, bore.part_m.head<2>(), tool_m, yaw,
                                            lift + j.world.height_m());
    ASSERT_TRUE(s.found) << s.reason;
    std::printf(
        "align look, part %d (%.0f um pin): view %.2f um off, pin %.2f um off, servo error %.0f nm off\n",
        j.index, 1e6 * j.side_m, 1e6 * view_off, 1e6 * (s.part_m.head<2>() - part).norm(),
        1e9 * (s.error_m - (part - bore_truth)).norm());
    EXPECT_GT((s.part_m.head<2>() - part).norm(), 1e-6) << "part " << j.index << ": the view is off";
    EXPECT_LT((s.error_m - (part - bore_truth)).norm(), 0.3e-6) << "part " << j.index;
    EXPECT_FALSE(s.converged);
    // The pin on the bore's axis: converged.
    const Eigen::Vector2d shift = bore_truth - part;
    pose.part_x_m += shift.x(), pose.part_y_m += shift.y();
    pose.tool_x_m += shift.x(), pose.tool_y_m += shift.y();
    const PinSighting on_axis = camera.look_align(pose, pin, j.target_m, bore.part_m.head<2>(),
                                                  tool_m + Eigen::Vector3d(shift.x(), shift.y(), 0.0), yaw,
                                                  lift + j.world.height_m());
    ASSERT_TRUE(on_axis.found) << on_axis.reason;
    EXPECT_LT(on_axis.error_m.norm(), 0.3e-6) << "part " << j.index;
    EXPECT_TRUE(on_axis.converged) << "part " << j.index;
  }
}

TEST(CellCamera, TellsAPinDownInItsBoreFromOneOnItsRimOrGone) {
  const AssemblyJob j = jobs(1, 63).front();
  const platform::PlatformConfig c = config_of(j);
  const PinModel pin{j.side_m, j.world.height_m()};
  const double top_inserted = j.world.height_m() - j.world.hole_depth_m;
  platform::CameraScenePose pose;
  pose.tool_x_m = j.target_m.x(), pose.tool_y_m = j.target_m.y();
  pose.tool_z_m = j.world.height_m() + 150e-6;  // retracted above the pin's former top
  pose.tool_yaw_rad = j.target_yaw_rad;
  pose.opening_m = j.world.gripper.max_opening_m;
  pose.part_yaw_rad = j.target_yaw_rad;
  CellCamera camera(on(), c, 3);

  // Down in its bore, 1.5 um off its axis.
  const Eigen::Vector2d in = j.target_m + Eigen::Vector2d(1.5e-6, -1.0e-6);
  pose.part_x_m = in.x(), pose.part_y_m = in.y(), pose.part_z_m = top_inserted - 0.5 * j.world.height_m();
  const PinSighting down =
      camera.look_placed(pose, pin, j.target_m, j.target_m, j.target_yaw_rad, top_inserted);
  ASSERT_TRUE(down.found) << down.reason;
  EXPECT_LT((down.part_m.head<2>() - in).norm(), 0.2e-6);
  EXPECT_NEAR(down.part_m.z(), pose.part_z_m, 10e-6);  // a bore's depth tells in from out
  std::printf("placed look: %.1f nm off in x-y, %.2f um in z\n", 1e9 * (down.part_m.head<2>() - in).norm(),
              1e6 * (down.part_m.z() - pose.part_z_m));

  // On the rim: beside its bore, a bore's depth higher.
  const Eigen::Vector2d rim = j.target_m + Eigen::Vector2d(0.0, 0.4 * j.side_m);
  pose.part_x_m = rim.x(), pose.part_y_m = rim.y(), pose.part_z_m = 0.5 * j.world.height_m();
  const PinSighting on_rim =
      camera.look_placed(pose, pin, j.target_m, j.target_m, j.target_yaw_rad, top_inserted);
  EXPECT_FALSE(on_rim.found);
  EXPECT_STREQ(on_rim.reason, "no pin top in focus at the height of a pin down in its bore");

  // Gone: stuck to a finger, up with the retract.
  pose.part_x_m = j.target_m.x(), pose.part_y_m = j.target_m.y();
  pose.part_z_m = pose.tool_z_m + 0.5 * j.world.height_m() - (j.world.hole_depth_m + 100e-6);
  EXPECT_FALSE(camera.look_placed(pose, pin, j.target_m, j.target_m, j.target_yaw_rad, top_inserted).found);
  EXPECT_EQ(camera.frames(), 9);
}

TEST(CellCamera, RefusesBadParameters) {
  CellCameraParams p = on();
  p.objective = "7x";
  EXPECT_THROW(p.validate(), InvalidParams);
  p = on();
  p.look_s = -1.0;
  try {
    p.validate();
    FAIL();
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("look_s"), std::string::npos) << e.what();
  }
  p = on();
  p.min_confidence = std::nan("");
  EXPECT_THROW(p.validate(), InvalidParams);
  p = on();
  p.focus_step_dof = 0.1;
  EXPECT_THROW(p.validate(), InvalidParams);
  p = on();
  p.view_error_m = -1e-6;
  try {
    p.validate();
    FAIL();
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("view_error_m"), std::string::npos) << e.what();
  }
  p = on();
  p.servo_converged_m = 0.0;
  EXPECT_THROW(p.validate(), InvalidParams);
}

}  // namespace
}  // namespace mc::cell
