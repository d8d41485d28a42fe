// Parking (stage.park_after_s): an axis arrived on a still target has its loop let go and its
// voltage held; friction holds it there; a target that moves resumes the loop without a jump. The
// console input drives X here (the rotary axis' own case is rotary_axis_test.cc's).
#include <gtest/gtest.h>

#include <cmath>

#include "microcobot/platform/platform.h"

namespace mc::platform {
namespace {

struct ParkingRig {
  PlatformConfig config;
  std::unique_ptr<Platform> platform;
  teleop::ConsoleInput in;
  explicit ParkingRig(double park_after_s = 0.1) {
    config.stage.park_after_s = park_after_s;
    platform = std::make_unique<Platform>(config);
    in.active = in.fresh = in.deadman = true;
    in.has_goal = true;
    in.goal_m = {config.stage.home_x_m, config.stage.home_y_m, config.stage.home_z_m};
    in.goal_speed_m_s = 200e-6;
    platform->set_operator([this](const runtime::TickInfo&) { platform->set_console_input(in); });
    platform->set_console_input(in);
  }
  double true_x() const { return platform->simulation().axes[0]->true_position_m(); }
};

TEST(Parking, AnAxisArrivedOnAStillTargetIsParkedHeldAndResumesWithoutAJump) {
  ParkingRig rig;
  rig.in.goal_m.x() += 100e-6;
  rig.platform->run(1.5);
  ASSERT_TRUE(rig.platform->parked(0)) << "arrived, still target";
  const double x = rig.true_x();
  EXPECT_NEAR(x, 100e-6, 20e-9);
  const auto u = rig.platform->recording().channel("u_x_V");
  for (std::size_t i = u.size() - 50; i < u.size(); ++i) EXPECT_EQ(u[i], u.back()) << "voltage held";
  rig.platform->run(2.0);
  EXPECT_NEAR(rig.true_x(), x, 1e-12) << "friction holds it: no creep";
  rig.in.goal_m.x() += 20e-6;
  rig.platform->run(0.01);
  EXPECT_FALSE(rig.platform->parked(0));
  EXPECT_LT(std::abs(rig.true_x() - x), 200e-6 * 0.01 + 0.5e-6)
      << "no jump on resuming: the new move's travel";
  rig.platform->run(1.0);
  EXPECT_NEAR(rig.true_x(), 120e-6, 20e-9);
}

TEST(Parking, ZeroNeverParksAndAFaultUnparks) {
  ParkingRig never(0.0);
  never.in.goal_m.x() += 50e-6;
  never.platform->run(1.0);
  EXPECT_FALSE(never.platform->parked(0));
  ParkingRig rig;
  rig.platform->run(0.5);
  ASSERT_TRUE(rig.platform->parked(2));
  rig.platform->fault_all();
  EXPECT_FALSE(rig.platform->parked(2));
  rig.platform->run(0.1);
  EXPECT_EQ(rig.platform->recording().channel("u_z_V").back(), 0.0) << "the fault's 0 V, not the park's";
}

}  // namespace
}  // namespace mc::platform
