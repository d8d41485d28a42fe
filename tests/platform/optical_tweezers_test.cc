#include "microcobot/devices/simulated_optical_tweezers.h"

#include <gtest/gtest.h>

#include <cmath>

#include "microcobot/cell/pick_place_operator.h"
#include "microcobot/cell/session.h"
#include "microcobot/core/error.h"
#include "microcobot/platform/platform.h"
#include "support/counting_allocator.h"

namespace mc::platform {
namespace {

// The default platform in the optical-trap scene.
PlatformConfig trap_scene() {
  PlatformConfig c;
  use_optical_trap_scene(c);
  return c;
}

std::size_t channel(const char* name) { return platform::telemetry_channel_index(name); }

// Standard deviation of a recorded channel over samples [from, to).
double stddev(const Recorder& r, const char* name, std::size_t from, std::size_t to) {
  const std::size_t c = channel(name);
  double sum = 0.0, sum_sq = 0.0;
  for (std::size_t i = from; i < to; ++i) sum += r.at(i, c);
  const double mean = sum / static_cast<double>(to - from);
  for (std::size_t i = from; i < to; ++i) sum_sq += (r.at(i, c) - mean) * (r.at(i, c) - mean);
  return std::sqrt(sum_sq / static_cast<double>(to - from));
}

// The optical-trap scene with the simulated operator's hand on the dual-stage master.
struct TrapRig {
  PlatformConfig config = trap_scene();
  Platform platform{config};
  devices::OperatorHand hand;
  TrapRig() {
    hand.deadman = true;
    platform.set_operator(
        [this](const runtime::TickInfo&) { platform.simulation().haptic->set_operator(hand); });
  }
  double last(const char* name) const {
    const Recorder& r = platform.recording();
    return r.at(r.size() - 1, channel(name));
  }
};

TEST(OpticalTweezersScene, TheProbeMeasuresTheBrownianForceOfTheTrap) {
  TrapRig rig;
  rig.hand.deadman = false;  // the stage holds still
  rig.platform.run(3.0);
  const Recorder& r = rig.platform.recording();
  ASSERT_GE(r.size(), 2900u);
  // The trap's measured force k (x - x_trap) has the equipartition spread sqrt(k_B T k)
  // (0.20 pN for 10 pN/um at 300 K). 2.5 s hold ~400 correlation times (1 / (2 pi f_c), 2.4 ms).
  const auto& trap = rig.config.optical_trap.trap;
  const double thermal_N =
      std::sqrt(microworld::OpticalTrap::kBoltzmann * trap.temperature_K * trap.trap_stiffness_N_per_m);
  const double fx = stddev(r, "contact_x_N", 500, r.size());
  const double fy = stddev(r, "contact_y_N", 500, r.size());
  std::printf("thermal %.3g N, measured x %.3g N, y %.3g N\n", thermal_N, fx, fy);
  EXPECT_NEAR(fx / thermal_N, 1.0, 0.15);
  EXPECT_NEAR(fy / thermal_N, 1.0, 0.15);
  EXPECT_LT(std::abs(rig.last("part_x_m") - rig.last("slave_x_m")),
            6 * thermal_N / trap.trap_stiffness_N_per_m);
}

TEST(OpticalTweezersScene, TheOperatorFeelsTheBrownianMotionThroughTheCoupling) {
  TrapRig rig;
  rig.platform.run(3.0);
  const Recorder& r = rig.platform.recording();
  // Engaged, the stage holds the trap still enough that the probe's force is the thermal one
  // (the tracking controller made it 1.9 times that: platform_config.h)...
  const auto& trap = rig.config.optical_trap.trap;
  const double thermal_N =
      std::sqrt(microworld::OpticalTrap::kBoltzmann * trap.temperature_K * trap.trap_stiffness_N_per_m);
  const double fx = stddev(r, "contact_x_N", 500, r.size());
  EXPECT_NEAR(fx / thermal_N, 1.0, 0.15);
  // ...and it reaches the hand scaled (1e10: 1 pN is 10 mN), not smoothed away: the coupling
  // passes 1 kHz in this scene (0.97 of its spread; with the pick-and-place's 30 Hz filter 0.55).
  const double hand = stddev(r, "haptic_force_x_N", 500, r.size());
  std::printf("probe %.3g N, hand %.3g N, ratio %.3f\n", fx, hand,
              hand / (rig.config.teleop.force_scale * fx));
  EXPECT_GT(hand / (rig.config.teleop.force_scale * fx), 0.85);
  EXPECT_LT(hand / (rig.config.teleop.force_scale * fx), 1.05);
  // The loop through the operator's finger stays stable (the scene's scales, platform_config.h):
  // the slave target stays within a fraction of a micrometre of home.
  for (std::size_t i = 500; i < r.size(); ++i)
    ASSERT_LT(std::abs(r.at(i, channel("target_x_m")) - rig.config.stage.home_x_m), 0.2e-6) << i;
}

TEST(OpticalTweezersScene, PushingTheProbeIntoTheStuckBeadIsFeltAsAForceOpposingTheMotion) {
  TrapRig rig;
  rig.platform.run(0.2);
  const auto& sim = rig.platform.simulation();
  const double start_x = sim.optical_tweezers->bead_m().x();
  const Eigen::Vector2d obstacle = sim.optical_tweezers->obstacle_m();
  const double touch_x = obstacle.x() - (rig.config.optical_trap.trap.bead_radius_m +
                                         rig.config.optical_trap.trap.obstacle_radius_m);
  // The hand moves 10 mm to +x over 2 s: the trap 5 um, 1.5 um past where the beads touch
  // (less the handle's give under the force, F / k_f).
  const double hand_travel_m = 10e-3;
  rig.platform.set_operator([&](const runtime::TickInfo& t) {
    const double s = std::clamp((t.t_s - 0.2) / 2.0, 0.0, 1.0);
    rig.hand.hand_m.x = hand_travel_m * s;
    sim.haptic->set_operator(rig.hand);
  });
  rig.platform.run(3.0);
  EXPECT_FALSE(rig.platform.faulted());
  const double trap_x = rig.last("slave_x_m");
  const double bead_x = rig.last("part_x_m");
  std::printf("start %.4g um, touch at %.4g um, trap %.4g um, bead %.4g um, contact %.3g N, hand %.3g N\n",
              1e6 * start_x, 1e6 * touch_x, 1e6 * trap_x, 1e6 * bead_x, rig.last("contact_x_N"),
              rig.last("haptic_force_x_N"));
  EXPECT_TRUE(sim.optical_tweezers->in_contact());
  EXPECT_GT(trap_x, touch_x + 0.5e-6);   // the trap went on past the contact...
  EXPECT_NEAR(bead_x, touch_x, 0.2e-6);  // ...the probe stopped against the stuck bead
  const double k = rig.config.optical_trap.trap.trap_stiffness_N_per_m;
  EXPECT_NEAR(rig.last("contact_x_N"), -k * (trap_x - bead_x), 1e-12);  // linear spring, Fig. 3.3
  EXPECT_LT(rig.last("contact_x_N"), -5e-12);                           // piconewtons, against the push
  EXPECT_LT(rig.last("haptic_force_x_N"), -0.05);                       // in the hand, against the push
  EXPECT_NEAR(rig.last("haptic_force_x_N") / (rig.config.teleop.force_scale * rig.last("contact_x_N")), 1.0,
              0.1);
}

TEST(OpticalTweezersScene, TheLoopPathNeitherAllocatesNorThrows) {
  TrapRig rig;
  rig.platform.loop().run_for(1000);
  std::size_t allocations = 0;
  {
    test::AllocationGuard guard;
    rig.platform.loop().run_for(10000);
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
}

TEST(OpticalTweezersScene, TheScriptedPickAndPlaceRefusesIt) {
  const PlatformConfig c = trap_scene();
  EXPECT_THROW(cell::Session(c, cell::SessionParams{}), InvalidParams);
  Platform p(c);
  EXPECT_THROW(cell::PickPlaceOperator(p, cell::PickPlaceOperatorParams{}), InvalidParams);
}

// The error's text for a configuration that must be refused.
std::string refusal(const PlatformConfig& c) {
  try {
    c.validate();
  } catch (const Error& e) {
    return e.what();
  }
  return "accepted";
}

TEST(OpticalTweezersScene, BadSceneParametersNameTheKey) {
  PlatformConfig on_the_probe = trap_scene();
  on_the_probe.optical_trap.obstacle_offset_x_m = 3e-6;  // the stuck bead on the probe
  EXPECT_NE(refusal(on_the_probe).find("optical_trap.obstacle_offset_x_m"), std::string::npos)
      << refusal(on_the_probe);
  PlatformConfig odd_step = trap_scene();
  odd_step.optical_trap.trap.dt_s = 3e-5;  // not a divisor of the 100 us loop period
  EXPECT_NE(refusal(odd_step).find("optical_trap.dt_s"), std::string::npos) << refusal(odd_step);
  PlatformConfig misspelt;
  misspelt.microworld = "optical_trap";
  EXPECT_NE(refusal(misspelt).find("microworld"), std::string::npos) << refusal(misspelt);
}

}  // namespace
}  // namespace mc::platform
