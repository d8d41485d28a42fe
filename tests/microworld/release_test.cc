#include "microcobot/microworld/release.h"

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/microworld/pick_place_world.h"

namespace mc::microworld {
namespace {

// The flat part of flat_part_scene() grasped on its seat at (0, 0), its edges held by the fingers,
// then set down (or held 100 um up) and the fingers opened: where does the part stay?
PickPlaceParams flat_at_its_seat() {
  PickPlaceParams p = flat_part_scene();
  p.target_m = p.part_start_m;
  return p;
}

struct Flat {
  PickPlaceWorld w;
  PickPlaceState s;
  Eigen::Vector3d g{0, 0, 1e-3};
  double yaw = 0.0;
  static constexpr double open = 500e-6, closed = 260e-6, dt = 1e-3;
  explicit Flat(PickPlaceParams p = flat_at_its_seat()) : w(std::move(p)), s(w.initial_state()) {}
  void step(double opening) { w.step(s, g, opening, dt, yaw); }
  void hold(double opening, double t) {
    for (double k = 0; k < t; k += dt) step(opening);
  }
  void move_z(double z, double opening) {
    while (std::abs(g.z() - z) > 1e-9) {
      g.z() += std::clamp(z - g.z(), -1e-6, 1e-6);
      step(opening);
    }
  }
  // Grasps the plate at half its thickness, lifts it 100 um and sets it down again (or not).
  void grasp_lift(bool set_down) {
    move_z(25e-6, open);
    hold(closed, 0.1);
    move_z(125e-6, closed);
    EXPECT_EQ(s.phase, PartPhase::kGrasped);
    if (set_down) move_z(25e-6, closed);
  }
};

TEST(Release, TheFlatPartsAdhesionFiguresAreThoseTheSceneStates) {
  const PickPlaceParams p = flat_part_scene();
  EXPECT_NEAR(p.finger_pulloff_N, 16.6e-6, 0.05e-6);
  EXPECT_NEAR(p.substrate_pulloff_N, 19.9e-6, 0.05e-6);
  EXPECT_NEAR(p.part_weight_N(), 0.375e-6, 0.001e-6);
  // m A (2 pi f)^2 = 3.83e-8 kg x 1 um x (2 pi 5 kHz)^2.
  EXPECT_NEAR(shake_force_N(p), 3.825e-8 * 1e-6 * std::pow(2 * M_PI * 5e3, 2), 1e-9);
  EXPECT_LT(release_margin(p, ReleaseStrategy::kOpen, false), 1.0);
  EXPECT_GT(release_margin(p, ReleaseStrategy::kShake, false), 1.0);
  EXPECT_GT(release_margin(p, ReleaseStrategy::kRoll, false), 1.0);
  // The default cube on its wetted seat lets go when the fingers merely open.
  EXPECT_GT(release_margin(PickPlaceParams{}, ReleaseStrategy::kOpen, false), 1.0);
}

TEST(Release, OpenedOnItsDrySeatTheFlatPartStaysOnAFingerAndComesUpWithIt) {
  Flat f;
  f.grasp_lift(true);
  f.hold(Flat::open, 0.1);
  EXPECT_EQ(f.s.phase, PartPhase::kStuckToFinger);
  f.move_z(300e-6, Flat::open);
  EXPECT_EQ(f.s.phase, PartPhase::kStuckToFinger);
  EXPECT_NEAR(f.s.part_m.z(), 300e-6, 1e-9) << "carried up by adhesion alone";
  EXPECT_FALSE(f.w.placed(f.s));
}

TEST(Release, ShakingTheOpenedFingersLeavesItOnItsSeat) {
  Flat f;
  f.grasp_lift(true);
  f.hold(Flat::open, 0.1);
  ASSERT_EQ(f.s.phase, PartPhase::kStuckToFinger);
  f.s.gripper.shaking = true;  // the drive's burst (SimulatedGripper::command_shake)
  f.hold(Flat::open, 0.01);
  f.s.gripper.shaking = false;
  EXPECT_EQ(f.s.phase, PartPhase::kOnSubstrate);
  f.move_z(300e-6, Flat::open);
  EXPECT_TRUE(f.w.placed(f.s));
  EXPECT_NEAR(f.s.part_m.z(), 25e-6, 1e-12);
}

TEST(Release, AShakeTooWeakForTheAdhesionLeavesItStuck) {
  PickPlaceParams p = flat_at_its_seat();
  p.gripper.shake_amplitude_m = 0.3e-6;  // 11 uN of inertia: 19.9 + 11 < 33.2 uN
  ASSERT_LT(release_margin(p, ReleaseStrategy::kShake, false), 1.0);
  Flat f(p);
  f.grasp_lift(true);
  f.hold(Flat::open, 0.1);
  f.s.gripper.shaking = true;
  f.hold(Flat::open, 0.05);
  EXPECT_EQ(f.s.phase, PartPhase::kStuckToFinger);
}

TEST(Release, ShakenInTheAirThePartDropsWhereItIs) {
  Flat f;
  f.grasp_lift(false);
  f.hold(Flat::open, 0.1);
  ASSERT_EQ(f.s.phase, PartPhase::kStuckToFinger);
  f.s.gripper.shaking = true;
  f.hold(Flat::open, 0.01);
  EXPECT_EQ(f.s.phase, PartPhase::kOnSubstrate);
  EXPECT_NEAR(f.s.part_m.z(), 25e-6, 1e-12);
}

TEST(Release, TurningTheOpenedFingersPeelsTheirContactWhileTheSeatHoldsThePart) {
  Flat f;
  f.grasp_lift(true);
  f.hold(Flat::open, 0.1);
  ASSERT_EQ(f.s.phase, PartPhase::kStuckToFinger);
  const double yaw0 = f.s.part_yaw_rad;
  // Below the peel angle: held, the contact not yet peeled.
  for (int i = 0; i < 4; ++i) {
    f.yaw += 0.002;
    f.step(Flat::open);
  }
  EXPECT_EQ(f.s.phase, PartPhase::kStuckToFinger);
  EXPECT_DOUBLE_EQ(f.s.part_yaw_rad, yaw0) << "the seat's friction holds the part's turn";
  for (int i = 0; i < 3; ++i) {
    f.yaw += 0.002;
    f.step(Flat::open);
  }
  EXPECT_EQ(f.s.phase, PartPhase::kOnSubstrate);
  EXPECT_DOUBLE_EQ(f.s.part_yaw_rad, yaw0);
  f.move_z(300e-6, Flat::open);
  EXPECT_TRUE(f.w.placed(f.s));
}

TEST(Release, OnASlipperySeatTheRolledPartTurnsWithTheFingersAndStaysStuck) {
  PickPlaceParams p = flat_at_its_seat();
  p.substrate_friction = 0.05;  // mu (F_s + W) r_s = 0.4e-10 N m < F_f w / 2 = 3.3e-10 N m
  ASSERT_LT(seat_moment_Nm(p), finger_peel_moment_Nm(p));
  ASSERT_LT(release_margin(p, ReleaseStrategy::kRoll, false), 1.0);
  Flat f(p);
  f.grasp_lift(true);
  f.hold(Flat::open, 0.1);
  const double yaw0 = f.s.part_yaw_rad;
  for (int i = 0; i < 20; ++i) {
    f.yaw += 0.002;
    f.step(Flat::open);
  }
  EXPECT_EQ(f.s.phase, PartPhase::kStuckToFinger);
  EXPECT_NEAR(f.s.part_yaw_rad, yaw0 + 0.04, 1e-12);
}

TEST(Release, APlacedFlatPartCountsOnlyWithinTheSeatsTolerance) {
  PickPlaceParams p = flat_part_scene();
  p.part_start_m = {0, 0, 0};
  p.target_m = {12e-6, 0, 0};
  Flat f(p);
  EXPECT_FALSE(f.w.placed(f.s)) << "12 um from a seat of 10 um tolerance";
  p.seat_tolerance_m = 15e-6;
  Flat g(p);
  EXPECT_TRUE(g.w.placed(g.s));
}

TEST(Release, NamesParseAndBadParametersAreRefusedByKey) {
  ReleaseStrategy r = ReleaseStrategy::kOpen;
  EXPECT_TRUE(parse_release("roll", r));
  EXPECT_EQ(r, ReleaseStrategy::kRoll);
  EXPECT_FALSE(parse_release("wiggle", r));
  PickPlaceParams p = flat_part_scene();
  p.roll_edge_fraction = 1.5;
  try {
    PickPlaceWorld w{p};
    FAIL();
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("roll_edge_fraction"), std::string::npos);
  }
  p = flat_part_scene();
  p.gripper.shake_frequency_Hz = 0.0;
  EXPECT_THROW(PickPlaceWorld{p}, InvalidParams);
}

}  // namespace
}  // namespace mc::microworld
