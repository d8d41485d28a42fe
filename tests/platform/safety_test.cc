// The platform's safety invariants, on the whole simulated platform (the coupling,
// the stage controller, the stick-slip axes, the gripper in its microworld), whatever the
// console or the scripted operator asks: nothing moves without the deadman, grip and contact
// forces stay under their limits, the finger tips never reach the substrate, an automatic
// sequence ends with every axis holding.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "microcobot/cell/pick_place_operator.h"
#include "microcobot/platform/platform.h"

namespace mc::platform {
// The file's own namespace: its helpers keep their names beside the other test files of the
// module in a unity build (MC_UNITY_TESTS).
namespace safety_test {
namespace {

std::size_t channel(const char* name) { return platform::telemetry_channel_index(name); }

// The largest value of a channel over the recording, from sample `from` on.
double peak(const Platform& p, const char* name, std::size_t from = 0) {
  const std::size_t c = channel(name);
  double m = 0.0;
  for (std::size_t i = from; i < p.recording().size(); ++i) m = std::max(m, std::abs(p.recording().at(i, c)));
  return m;
}

double contact_peak(const Platform& p, std::size_t from = 0) {
  double m = 0.0;
  const std::size_t cx = channel("contact_x_N"), cy = channel("contact_y_N"), cz = channel("contact_z_N");
  for (std::size_t i = from; i < p.recording().size(); ++i)
    m = std::max(m, std::hypot(p.recording().at(i, cx), p.recording().at(i, cy), p.recording().at(i, cz)));
  return m;
}

double last(const Platform& p, const char* name) {
  return p.recording().at(p.recording().size() - 1, channel(name));
}

// The platform driven by the console (world coordinates, as the live console sends them).
struct ConsoleRig {
  PlatformConfig config;
  std::unique_ptr<Platform> platform;
  teleop::ConsoleInput in;
  explicit ConsoleRig(const microworld::PickPlaceParams& world = {}) {
    config.world = world;
    platform = std::make_unique<Platform>(config);
    in.active = true;
    in.fresh = true;
    platform->set_operator([this](const runtime::TickInfo&) { platform->set_console_input(in); });
  }
  Eigen::Vector3d tip() const { return platform->simulation().gripper->tip_position_m(); }
  void go_to(const Eigen::Vector3d& goal, double seconds) {
    in.deadman = true;
    in.has_goal = true;
    in.goal_m = goal;
    in.goal_speed_m_s = 1e-3;
    platform->run(seconds);
    in.has_goal = false;
  }
};

TEST(Safety, WithoutTheDeadmanNeitherTheStageNorTheGripperMoveWhateverTheConsoleSends) {
  ConsoleRig rig;
  rig.platform->run(0.2);
  const Eigen::Vector3d before = rig.tip();
  rig.in.deadman = false;
  rig.in.velocity_m_s = {1e-3, -1e-3, -1e-3};
  rig.in.has_gripper = true;
  rig.in.gripper_opening_m = 0.0;  // the slider slammed shut
  rig.platform->run(1.0);
  EXPECT_LT((rig.tip() - before).norm(), 20e-9);
  EXPECT_DOUBLE_EQ(last(*rig.platform, "gripper_command_m"), 600e-6);
  EXPECT_NEAR(last(*rig.platform, "gripper_opening_m"), 600e-6, 1e-9);
  rig.in.has_goal = true;
  rig.in.goal_m = {0, 0, 100e-6};  // click-to-go without the deadman
  rig.platform->run(0.5);
  EXPECT_LT((rig.tip() - before).norm(), 20e-9);
}

TEST(Safety, ASliderSlammedShutOnAPartGripsAtTheLimitAndPressingItDownStaysUnderTheContactLimit) {
  ConsoleRig rig;
  const auto& w = rig.config.world;
  rig.go_to({w.part_start_m.x(), w.part_start_m.y(), 100e-6}, 1.5);
  ASSERT_LT((rig.tip() - Eigen::Vector3d(0, 0, 100e-6)).norm(), 2e-6);
  const std::size_t from = rig.platform->recording().size();
  rig.in.has_gripper = true;
  rig.in.gripper_opening_m = 0.0;
  rig.platform->run(0.5);
  const double limit = w.grip_force_limit_N;
  EXPECT_LE(peak(*rig.platform, "grip_force_N", from), limit * (1 + 1e-9));
  EXPECT_GT(last(*rig.platform, "grip_force_N"), 0.95 * limit)
      << "a force-controlled close, not an open hand";
  // Lift, then press the held part into the substrate and drag it sideways at full speed.
  rig.go_to({0, 0, 300e-6}, 0.5);
  ASSERT_EQ(rig.platform->simulation().gripper->world_state().phase, microworld::PartPhase::kGrasped);
  rig.in.velocity_m_s = {0, 0, -1e-3};
  rig.platform->run(1.0);
  rig.in.velocity_m_s = {1e-3, 0, 0};
  rig.platform->run(0.3);
  EXPECT_LE(peak(*rig.platform, "grip_force_N", from), limit * (1 + 1e-9));
  EXPECT_LE(contact_peak(*rig.platform, from), w.contact_force_limit_N);
  EXPECT_GE(rig.tip().z(), w.min_tip_height_m - 1e-6);
}

TEST(Safety, DrivingTheFingerTipsIntoTheSubstrateStopsAtTheFloor) {
  ConsoleRig rig;
  const auto& w = rig.config.world;
  rig.go_to({-1e-3, 0.5e-3, 200e-6}, 1.5);  // away from the part
  rig.in.deadman = true;
  rig.in.velocity_m_s = {0, 0, -1e-3};
  rig.platform->run(1.0);
  EXPECT_NEAR(rig.tip().z(), w.min_tip_height_m, 1e-6);
  EXPECT_FALSE(rig.platform->simulation().gripper->world_state().crashed);
  EXPECT_EQ(contact_peak(*rig.platform), 0.0);
  rig.in.has_goal = true;  // a click below the substrate
  rig.in.goal_m = {-1e-3, 0.5e-3, -2e-3};
  rig.platform->run(0.5);
  EXPECT_GE(rig.tip().z(), w.min_tip_height_m - 1e-6);
}

// The pin-in-hole scene's scripted operator inserts the pin, under the limits, then lets go:
// every axis holds where it ended.
TEST(Safety, TheScriptedPinInHoleInsertsThePinUnderTheLimitsAndEndsHolding) {
  PlatformConfig config;
  config.world = microworld::pin_in_hole_scene();
  config.world.target_m.x() = 0.3e-3;  // a short transport keeps the test short
  Platform p(config);
  cell::PickPlaceOperator op(p, cell::PickPlaceOperatorParams{});
  p.set_operator([&](const runtime::TickInfo& t) { op.act(t); });
  for (int i = 0; i < 240 && !op.done() && !op.gave_up(); ++i) p.run(0.5);
  ASSERT_TRUE(op.done()) << "gave up in " << cell::PickPlaceOperator::name(op.failed_phase()) << ": "
                         << cell::PickPlaceOperator::give_up_reason(op.failed_phase());
  const auto* g = p.simulation().gripper;
  EXPECT_TRUE(g->world().inserted(g->world_state()));
  EXPECT_LT(g->world().placement_error_m(g->world_state()), 10e-6);
  EXPECT_LE(peak(p, "grip_force_N"), config.world.grip_force_limit_N * (1 + 1e-9));
  EXPECT_LE(contact_peak(p), config.world.contact_force_limit_N);
  EXPECT_FALSE(g->world_state().crashed);
  const Eigen::Vector3d end = g->tip_position_m();
  p.run(3.0);
  EXPECT_LT((g->tip_position_m() - end).norm(), 50e-9) << "the stage drifts after the sequence";
  EXPECT_FALSE(p.teleop().engaged);
}

}  // namespace
}  // namespace safety_test
}  // namespace mc::platform
