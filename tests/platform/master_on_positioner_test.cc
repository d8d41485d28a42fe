// The haptic master on the parallel positioner (`master_drives: positioner`): the handle moves the
// part's plate through the coupling (its scale, deadman, clutch and freshness), the console's dial
// turns it about the vertical, the gripper holds on the Cartesian robot, and no input raises the
// seat into the finger tips.

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <numbers>

#include "microcobot/core/error.h"
#include "microcobot/devices/carried_seat.h"
#include "microcobot/motion/pose.h"
#include "microcobot/platform/platform.h"
#include "support/counting_allocator.h"
#include "support/test_support.h"

namespace mc::platform {
namespace {

constexpr double kMasterDeg = std::numbers::pi / 180.0;

PlatformConfig master_config() {
  PlatformConfig c;
  c.positioner = "parallel";
  c.master_drives = "positioner";
  return c;
}

// The platform with the simulated operator's hand on the haptic master and the console's input
// (not holding control unless `console.active`).
struct MasterRig {
  explicit MasterRig(const PlatformConfig& c = master_config()) : config(c), platform(config) {
    platform.set_operator([this](const runtime::TickInfo&) {
      platform.simulation().haptic->set_operator(hand);
      platform.set_console_input(console);
    });
  }
  Eigen::Vector3d stage() const {
    const auto& a = platform.simulation().axes;
    return {a[0]->position_m(), a[1]->position_m(), a[2]->position_m()};
  }
  const motion::PlatformTransform& plate() const { return platform.simulation().positioner->true_pose(); }
  void run_s(double s) { platform.loop().run_for(static_cast<int>(s / config.loop.period_s())); }

  PlatformConfig config;
  Platform platform;
  devices::OperatorHand hand;
  teleop::ConsoleInput console;
};

TEST(MasterOnPositioner, TheConfigurationNamesWhatTheMasterDrives) {
  EXPECT_NO_THROW(master_config().validate());
  test::TempDir dir;
  for (const auto& [yaml, given] : {std::pair{"master_drives: gripper\n", "'gripper'"},
                                    std::pair{"master_drives: positioner\n", "positioner: cartesian"}}) {
    std::ofstream(dir / "platform.yaml") << yaml;
    try {
      load_platform_config(dir / "platform.yaml");
      FAIL() << "accepted " << yaml;
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("master_drives"), std::string::npos) << what;
      EXPECT_NE(what.find(given), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

TEST(MasterOnPositioner, TheHandleMovesThePartsPlateAtTheMotionScaleWhileTheGripperHolds) {
  MasterRig rig;
  rig.run_s(0.2);  // the legs power up
  const Eigen::Vector3d stage0 = rig.stage();
  const Eigen::Vector3d part0 = rig.platform.simulation().gripper->part_position_m();
  const Eigen::Vector3d plate0 = rig.plate().d;
  rig.hand.deadman = true;
  rig.run_s(0.1);  // engaged where the hand is: nothing moves
  EXPECT_LT((rig.plate().d - plate0).norm(), 0.1e-6);
  rig.hand.hand_m = {5e-3, -3e-3};  // 5 mm and -3 mm of hand: 50 um and -30 um of plate
  rig.run_s(1.5);
  const double scale = rig.config.teleop.motion_scale;
  const Eigen::Vector3d moved = rig.plate().d - plate0;
  std::printf("the handle's (5, -3) mm moved the plate (%.3f, %.3f, %.3f) um, the gripper %.1f nm\n",
              1e6 * moved.x(), 1e6 * moved.y(), 1e6 * moved.z(), 1e9 * (rig.stage() - stage0).norm());
  EXPECT_NEAR(moved.x(), scale * 5e-3, 0.5e-6);
  EXPECT_NEAR(moved.y(), scale * -3e-3, 0.5e-6);
  EXPECT_NEAR(moved.z(), 0.0, 0.5e-6);
  EXPECT_LT((rig.platform.simulation().gripper->part_position_m() - part0 - moved).norm(), 0.1e-6)
      << "the part rode on it";
  EXPECT_LT((rig.stage() - stage0).norm(), 0.1e-6) << "the gripper held";
  // The deadman released: the plate holds at once where it is.
  rig.hand.hand_m = {-5e-3, 3e-3};
  rig.run_s(0.05);
  ASSERT_TRUE(rig.platform.positioner()->following());
  rig.hand.deadman = false;
  rig.run_s(0.002);
  EXPECT_FALSE(rig.platform.positioner()->following());
  EXPECT_FALSE(rig.platform.positioner()->moving());
  const Eigen::Vector3d held = rig.plate().d;
  rig.run_s(0.5);
  EXPECT_LT((rig.plate().d - held).norm(), 0.3e-6);
  // Indexing: the clutch pressed, the hand comes back and the plate stays; released, it moves on.
  rig.hand.deadman = true, rig.hand.clutch = true;
  rig.hand.hand_m = {0.0, 0.0};
  rig.run_s(0.3);
  EXPECT_LT((rig.plate().d - held).norm(), 0.3e-6);
  rig.hand.clutch = false;
  rig.run_s(0.1);
  rig.hand.hand_m = {2e-3, 0.0};
  rig.run_s(1.0);
  EXPECT_NEAR(rig.plate().d.x() - held.x(), scale * 2e-3, 0.5e-6);
}

TEST(MasterOnPositioner, TheConsolesDialTurnsThePlateAboutTheVerticalNotTheGripper) {
  MasterRig rig;
  rig.run_s(0.2);
  const double yaw0 = rig.platform.yaw_rad();
  rig.console.fresh = true;
  rig.console.theta_rate_rad_s = 0.5 * kMasterDeg;  // the dial, without its deadman: nothing turns
  rig.run_s(0.5);
  EXPECT_NEAR(devices::CarriedSeat{rig.plate()}.yaw_rad(), 0.0, 1e-6);
  rig.console.deadman = true;
  rig.run_s(1.0);
  std::printf("the dial at 0.5 deg/s for 1 s turned the plate %.4f deg\n",
              devices::CarriedSeat{rig.plate()}.yaw_rad() / kMasterDeg);
  EXPECT_NEAR(devices::CarriedSeat{rig.plate()}.yaw_rad(), 0.5 * kMasterDeg, 0.05 * kMasterDeg);
  EXPECT_NEAR(rig.platform.yaw_rad(), yaw0, 1e-6) << "the gripper's rotary axis held";
  rig.console.deadman = false;
  rig.run_s(0.002);
  EXPECT_FALSE(rig.platform.positioner()->following());
}

TEST(MasterOnPositioner, NoInputRaisesTheSeatIntoTheTips) {
  PlatformConfig c = master_config();
  c.stage.home_x_m = -1.5e-3;  // over the bare substrate, 40 um above it
  c.stage.home_z_m = 40e-6;
  MasterRig rig(c);
  rig.run_s(0.2);
  rig.hand.deadman = true;
  rig.run_s(0.1);
  rig.hand.jog_m_s = 50e-6;  // the thumb wheel up: the plate rises toward the tips
  rig.run_s(1.5);
  const auto& g = *rig.platform.simulation().gripper;
  const double clearance = g.seat().to_seat(g.tip_position_m()).z();
  const double floor = c.world.min_tip_height_m;
  std::printf("the thumb wheel up: the plate stopped %.3f um under the tips (floor %.0f um)\n",
              1e6 * clearance, 1e6 * floor);
  EXPECT_GT(clearance, floor - 0.1e-6);
  EXPECT_LT(clearance, floor + 0.5e-6) << "it rose to the floor";
  EXPECT_FALSE(g.world_state().crashed);
  rig.hand.jog_m_s = -50e-6;  // and down again
  rig.run_s(0.5);
  EXPECT_GT(g.seat().to_seat(g.tip_position_m()).z(), floor + 10e-6);
}

TEST(MasterOnPositioner, TheConsoleTakingControlHoldsThePlateAndDrivesTheGripperAgain) {
  MasterRig rig;
  rig.run_s(0.2);
  rig.hand.deadman = true;
  rig.run_s(0.1);
  rig.hand.hand_m = {5e-3, 0.0};
  rig.run_s(0.2);
  ASSERT_TRUE(rig.platform.positioner()->following());
  rig.console.active = true, rig.console.fresh = true, rig.console.deadman = true;
  rig.console.velocity_m_s = {20e-6, 0.0, 0.0};  // the console's joystick: the gripper
  const Eigen::Vector3d stage0 = rig.stage();
  rig.run_s(0.002);
  EXPECT_FALSE(rig.platform.positioner()->following());
  const Eigen::Vector3d held = rig.plate().d;
  rig.run_s(0.5);
  EXPECT_LT((rig.plate().d - held).norm(), 0.3e-6) << "the plate held";
  EXPECT_NEAR(rig.stage().x() - stage0.x(), 10e-6, 2e-6) << "the console drove the gripper";
}

TEST(MasterOnPositioner, TheLoopPathAllocatesNothingWhileTheMasterAndTheDialDriveThePlate) {
  MasterRig rig;
  rig.run_s(0.2);
  rig.hand.deadman = true;
  rig.run_s(0.1);  // warm-up: first touches
  std::size_t allocations = 0;
  {
    test::AllocationGuard guard;
    rig.hand.hand_m = {3e-3, 1e-3};
    rig.run_s(0.3);
    rig.console.fresh = rig.console.deadman = true;
    rig.console.theta_rate_rad_s = 0.5 * kMasterDeg;
    rig.run_s(0.2);
    rig.hand.deadman = rig.console.deadman = false;  // released: held, the coupling re-anchored
    rig.run_s(0.1);
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_GT(rig.plate().d.norm(), 5e-6) << "it moved meanwhile";
}

}  // namespace
}  // namespace mc::platform
