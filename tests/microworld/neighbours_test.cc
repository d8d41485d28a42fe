#include "microcobot/microworld/neighbours.h"

#include <gtest/gtest.h>

#include <cmath>

#include "microcobot/core/error.h"
#include "microcobot/microworld/pick_place_world.h"

namespace mc::microworld {
namespace {

TEST(Neighbours, OverlapIsTheLeastPenetrationAlongTheRectanglesSides) {
  Eigen::Vector2d out;
  const Footprint a{{0, 0}, {100e-6, 100e-6}, 0.0};
  EXPECT_NEAR(overlap(a, {{190e-6, 20e-6}, {100e-6, 100e-6}, 0.0}, out), 10e-6, 1e-15);
  EXPECT_NEAR(out.x(), 1.0, 1e-12) << "out of a along +x";
  EXPECT_NEAR(overlap(a, {{-195e-6, 0}, {100e-6, 100e-6}, 0.0}, out), 5e-6, 1e-15);
  EXPECT_NEAR(out.x(), -1.0, 1e-12);
  EXPECT_DOUBLE_EQ(overlap(a, {{201e-6, 0}, {100e-6, 100e-6}, 0.0}, out), 0.0);
  // A square turned 45 deg reaches 141 um along x: its corner 10 um into a's side at x = 100 um.
  const double r = 100e-6 * std::sqrt(2.0);
  EXPECT_NEAR(overlap(a, {{100e-6 + r - 10e-6, 0}, {100e-6, 100e-6}, M_PI / 4}, out), 10e-6, 1e-12);
  // Diagonally beside the corner of a, inside the box of a's corners but apart from a turned square.
  EXPECT_DOUBLE_EQ(
      overlap({{0, 0}, {100e-6, 100e-6}, M_PI / 4}, {{140e-6, 140e-6}, {20e-6, 20e-6}, 0.0}, out), 0.0);
}

// The default cube at (0, 0) with a neighbour pin 600 um tall at x = 500 um.
PickPlaceParams with_neighbour(double x) {
  PickPlaceParams p;
  p.neighbour_count = 1;
  p.neighbours[0] = {{x, 0.0}, 0.0, 200e-6, 600e-6};
  return p;
}

TEST(Neighbours, TheFingersStrikeANeighbourBelowItsTopAndFeelItsStiffness) {
  const PickPlaceWorld w{with_neighbour(500e-6)};
  auto s = w.initial_state();
  // Open 600 um over the cube: the fingers' outer faces at 350 um, the neighbour's face at 400 um.
  auto out = w.step(s, {0, 0, 50e-6}, 600e-6, 1e-3);
  EXPECT_FALSE(out.touching_neighbour);
  // 80 um towards it: the finger's outer face at 430 um, 30 um into the neighbour.
  out = w.step(s, {80e-6, 0, 50e-6}, 600e-6, 1e-3);
  EXPECT_TRUE(out.touching_neighbour);
  EXPECT_NEAR(out.force_on_gripper_N.x(), -1e5 * 30e-6, 1e-9) << "pushed back, away from it";
  EXPECT_EQ(s.neighbour_contacts, 1);
  // Above its top the fingers pass over it.
  out = w.step(s, {80e-6, 0, 650e-6}, 600e-6, 1e-3);
  EXPECT_FALSE(out.touching_neighbour);
}

TEST(Neighbours, AHeldPartCarriedLowStrikesANeighbourAndAbovePassesOver) {
  const PickPlaceWorld w{with_neighbour(900e-6)};
  auto s = w.initial_state();
  for (int i = 0; i < 100; ++i) w.step(s, {0, 0, 50e-6}, 260e-6, 1e-3);              // grasp
  for (int i = 1; i <= 100; ++i) w.step(s, {0, 0, 50e-6 + i * 1e-6}, 260e-6, 1e-3);  // lift 100 um
  ASSERT_EQ(s.phase, PartPhase::kGrasped);
  // Across to x = 620 um: the 300 um cube's face at 770 um, 30 um into the neighbour's (800 um).
  PickPlaceOutput out;
  for (int i = 1; i <= 620; ++i) out = w.step(s, {i * 1e-6, 0, 150e-6}, 260e-6, 1e-3);
  EXPECT_TRUE(out.touching_neighbour);
  EXPECT_LT(out.force_on_gripper_N.x(), 0.0);
  // Lifted so that its bottom clears the neighbour's 600 um top: free.
  for (int i = 1; i <= 600; ++i) out = w.step(s, {620e-6, 0, 150e-6 + i * 1e-6}, 260e-6, 1e-3);
  EXPECT_FALSE(out.touching_neighbour);
}

TEST(Neighbours, ANeighbourWithoutAPlaceOrATopIsRefused) {
  PickPlaceParams p = with_neighbour(500e-6);
  p.neighbours[0].top_z_m = 0.0;
  EXPECT_THROW(PickPlaceWorld{p}, InvalidParams);
  p = with_neighbour(500e-6);
  p.neighbour_count = 9;
  EXPECT_THROW(PickPlaceWorld{p}, InvalidParams);
}

}  // namespace
}  // namespace mc::microworld
