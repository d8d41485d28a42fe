#include "microcobot/microworld/pick_place_world.h"

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "support/counting_allocator.h"

namespace mc::microworld {
namespace {

// Moves the gripper in a straight line from `from` to `to` in 1 um steps, opening command and
// fingers' yaw fixed.
PickPlaceOutput move(const PickPlaceWorld& w, PickPlaceState& s, Eigen::Vector3d& at,
                     const Eigen::Vector3d& to, double opening, double yaw = 0.0) {
  PickPlaceOutput out;
  const int n = std::max(1, static_cast<int>((to - at).norm() / 1e-6));
  const Eigen::Vector3d from = at;
  for (int i = 1; i <= n; ++i) {
    at = from + (to - from) * (static_cast<double>(i) / n);
    out = w.step(s, at, opening, 1e-3, yaw);
  }
  return out;
}

// Holds the gripper still for `t` seconds with an opening command.
PickPlaceOutput hold(const PickPlaceWorld& w, PickPlaceState& s, const Eigen::Vector3d& at, double opening,
                     double t) {
  PickPlaceOutput out;
  for (double k = 0; k < t; k += 1e-3) out = w.step(s, at, opening, 1e-3);
  return out;
}

TEST(SurfaceForces, AdhesionDominatesWeightAtThisScale) {
  const PickPlaceParams p;
  EXPECT_NEAR(p.part_weight_N(), 2.25e-6, 0.01e-6);
  EXPECT_GT(p.substrate_pulloff_N, 10 * p.part_weight_N());
  EXPECT_GT(2 * p.finger_pulloff_N, p.part_weight_N());  // a part let go in the air stays on a finger
}

TEST(PickPlaceWorld, PickTransportPlaceAndReleaseDespiteAdhesion) {
  const PickPlaceWorld w{PickPlaceParams{}};
  auto s = w.initial_state();
  Eigen::Vector3d g(0, 0, 1e-3);
  const double open = 500e-6, closed = 260e-6;
  move(w, s, g, {0, 0, 50e-6}, open);
  // Closing 240 um takes 48 ms at the 5 mm/s slew limit, then the 2 ms first-order tail settles.
  auto out = hold(w, s, g, closed, 0.1);
  EXPECT_TRUE(out.part_between_fingers);
  EXPECT_NEAR(out.grip_force_N, 0.5 * 50.0 * 40e-6, 1e-6);  // k (w - o) / 2 = 1 mN
  EXPECT_DOUBLE_EQ(out.opening_m, 300e-6);                  // the part blocks the fingers
  move(w, s, g, {0, 0, 250e-6}, closed);
  EXPECT_EQ(s.phase, PartPhase::kGrasped);
  EXPECT_NEAR(s.part_m.z(), 150e-6 + 200e-6, 1e-9);
  move(w, s, g, {2e-3, 0, 250e-6}, closed);
  move(w, s, g, {2e-3, 0, 40e-6}, closed);  // set down (10 um of press: fingers slide)
  EXPECT_NEAR(s.part_m.z(), 150e-6, 1e-12);
  hold(w, s, g, open, 0.05);
  EXPECT_EQ(s.phase, PartPhase::kOnSubstrate);
  move(w, s, g, {2e-3, 0, 1e-3}, open);
  EXPECT_EQ(s.phase, PartPhase::kOnSubstrate);
  EXPECT_LT(w.placement_error_m(s), 1e-9);
  EXPECT_FALSE(s.crashed);
}

TEST(PickPlaceWorld, AWeakGripSlipsInsteadOfLifting) {
  const PickPlaceWorld w{PickPlaceParams{}};
  auto s = w.initial_state();
  Eigen::Vector3d g(0, 0, 50e-6);
  // A 2 um squeeze grips with 50 uN: its friction capacity 2 * 0.3 * 50 = 30 uN is below the
  // 36 uN of substrate adhesion + weight.
  hold(w, s, g, 298e-6, 0.05);
  const auto out = move(w, s, g, {0, 0, 200e-6}, 298e-6);
  EXPECT_EQ(s.phase, PartPhase::kOnSubstrate);
  EXPECT_NEAR(s.part_m.z(), 150e-6, 1e-12);
  EXPECT_LT(out.force_on_gripper_N.z(), 0.0);  // the slipping fingers feel the friction
}

TEST(PickPlaceWorld, OpenedInTheAirThePartSticksToAFingerUntilItTouchesDown) {
  const PickPlaceWorld w{PickPlaceParams{}};
  auto s = w.initial_state();
  Eigen::Vector3d g(0, 0, 50e-6);
  hold(w, s, g, 260e-6, 0.05);
  move(w, s, g, {0, 0, 400e-6}, 260e-6);
  hold(w, s, g, 500e-6, 0.05);
  EXPECT_EQ(s.phase, PartPhase::kStuckToFinger);
  move(w, s, g, {1e-3, 0, 400e-6}, 500e-6);
  EXPECT_NEAR(s.part_m.x(), 1e-3, 1e-12);  // carried by adhesion alone
  move(w, s, g, {1e-3, 0, 0.0}, 500e-6);
  EXPECT_EQ(s.phase, PartPhase::kOnSubstrate);
  move(w, s, g, {1e-3, 0, 1e-3}, 500e-6);
  EXPECT_NEAR(s.part_m.x(), 1e-3, 1e-12);
}

TEST(PickPlaceWorld, TipsIntoTheSubstrateAreACrashWithAStiffReaction) {
  const PickPlaceWorld w{PickPlaceParams{}};
  auto s = w.initial_state();
  Eigen::Vector3d g(1e-3, 1e-3, 10e-6);
  const auto out = move(w, s, g, {1e-3, 1e-3, -1e-6}, 500e-6);
  EXPECT_TRUE(s.crashed);
  EXPECT_NEAR(out.force_on_gripper_N.z(), 1e5 * 1e-6, 1e-9);
}

TEST(PickPlaceWorld, SteppingNeverAllocatesAndParamsAreValidated) {
  const PickPlaceWorld w{PickPlaceParams{}};
  auto s = w.initial_state();
  std::size_t n = 0;
  {
    test::AllocationGuard guard;
    for (int i = 0; i < 1000; ++i) w.step(s, Eigen::Vector3d(0, 0, 50e-6), 260e-6, 1e-4);
    n = guard.allocations();
  }
  EXPECT_EQ(n, 0u);
  PickPlaceParams bad;
  bad.part_side_m = 700e-6;  // does not fit in the open gripper
  EXPECT_THROW(PickPlaceWorld{bad}, InvalidParams);
}

// The pin-in-hole scene: a 200 um pin (600 um tall) into a 220 um hole 300 um deep at the target.
struct Pin {
  PickPlaceWorld w{pin_in_hole_scene()};
  PickPlaceState s = w.initial_state();
  Eigen::Vector3d g{0, 0, 1e-3};
  static constexpr double open = 400e-6, closed = 160e-6;
  // Grasps the pin 50 um above its middle and carries it 200 um higher, over (x, y).
  void carry_over(double x, double y) {
    move(w, s, g, {0, 0, 350e-6}, open);
    hold(w, s, g, closed, 0.1);
    move(w, s, g, {0, 0, 550e-6}, closed);
    EXPECT_EQ(s.phase, PartPhase::kGrasped);
    move(w, s, g, {x, y, 550e-6}, closed);
  }
};

TEST(PinInHole, AnAlignedPinGoesDownToTheBottomOfTheHoleAndStaysThereWhenReleased) {
  Pin pin;
  EXPECT_NEAR(pin.s.part_m.z(), 300e-6, 1e-12) << "the pin stands on the substrate";
  pin.carry_over(2e-3 + 8e-6, -6e-6);  // within the 10 um of play
  move(pin.w, pin.s, pin.g, {2e-3 + 8e-6, -6e-6, 40e-6}, Pin::closed);
  EXPECT_NEAR(pin.s.part_m.z(), 0.0, 1e-12) << "its bottom on the hole's bottom, 300 um down";
  EXPECT_TRUE(pin.w.inserted(pin.s));
  EXPECT_FALSE(pin.s.crashed) << "the fingers held it above the substrate";
  hold(pin.w, pin.s, pin.g, Pin::open, 0.1);
  move(pin.w, pin.s, pin.g, {2e-3 + 8e-6, -6e-6, 1e-3}, Pin::open);
  EXPECT_EQ(pin.s.phase, PartPhase::kOnSubstrate);
  EXPECT_TRUE(pin.w.inserted(pin.s));
  EXPECT_LT(pin.w.placement_error_m(pin.s), 10e-6 * std::sqrt(2.0));
}

TEST(PinInHole, AMisalignedPinLandsOnTheRimAndTheFingersFeelIt) {
  Pin pin;
  pin.carry_over(2e-3 + 30e-6, 0);  // 30 um off: more than the 10 um of play
  const auto out = move(pin.w, pin.s, pin.g, {2e-3 + 30e-6, 0, 340e-6}, Pin::closed);
  EXPECT_NEAR(pin.s.part_m.z(), 300e-6, 1e-12) << "stopped on the rim";
  EXPECT_FALSE(pin.w.inserted(pin.s));
  EXPECT_GT(out.force_on_gripper_N.z(), 0.0) << "the press comes back to the fingers";
}

TEST(PinInHole, TheHolesWallsStopTheInsertedPinSideways) {
  Pin pin;
  pin.carry_over(2e-3, 0);
  move(pin.w, pin.s, pin.g, {2e-3, 0, 100e-6}, Pin::closed);
  ASSERT_TRUE(pin.w.inserted(pin.s));
  const auto out = move(pin.w, pin.s, pin.g, {2e-3 + 50e-6, 0, 100e-6}, Pin::closed);
  EXPECT_NEAR(pin.s.part_m.x(), 2e-3 + 10e-6, 1e-12) << "against the wall";
  // The wall stops the pin with 1e5 N/m x 1 um = 0.1 N; the fingers feel at most what holds
  // the pin in them, 2 mu F_grip: beyond it the pin slips between them.
  const double holds = 2 * pin.w.params().finger_friction * out.grip_force_N;
  ASSERT_GT(out.grip_force_N, 0.0);
  EXPECT_NEAR(out.force_on_gripper_N.x(), -holds, 1e-12)
      << "pressed into the wall, the pin slips in the fingers";
  const double k2 = 2 * pin.w.params().gripper.finger_stiffness_N_m;
  EXPECT_NEAR(pin.s.finger_deflection_m.x(), -holds / k2, 1e-12) << "bent as far as the grip holds";
  // Pulled out, it is free again: the fingers spring back with it.
  move(pin.w, pin.s, pin.g, {2e-3 + 50e-6, 0, 600e-6}, Pin::closed);
  EXPECT_FALSE(pin.w.inserted(pin.s));
  EXPECT_NEAR(pin.s.part_m.x(), 2e-3 + 10e-6 + holds / k2, 1e-12)
      << "it slipped in the fingers by what their bend did not take";
  EXPECT_EQ(pin.s.finger_deflection_m.norm(), 0.0);
}

// Contact force by vision: along their closing axis the fingers are benders, so a pin
// pushed into its hole's wall bends them (both together, 2 k_finger) before it slips in them.
TEST(PinInHole, PushedIntoTheWallTheFingersBendBeforeThePinSlipsAndSpringBack) {
  Pin pin;
  pin.carry_over(2e-3, 0);
  move(pin.w, pin.s, pin.g, {2e-3, 0, 100e-6}, Pin::closed);
  ASSERT_TRUE(pin.w.inserted(pin.s));
  const double offset = pin.s.offset_m.x(), k2 = 2 * pin.w.params().gripper.finger_stiffness_N_m;
  // 3 um past the wall (10 um of play): 2 k x 3 um = 300 uN, under the 600 uN the grip holds.
  auto out = move(pin.w, pin.s, pin.g, {2e-3 + 13e-6, 0, 100e-6}, Pin::closed);
  const double holds = 2 * pin.w.params().finger_friction * out.grip_force_N;
  ASSERT_GT(holds, k2 * 3e-6);
  EXPECT_NEAR(out.force_on_gripper_N.x(), -k2 * 3e-6, 1e-12) << "the bend's spring, not the wall's";
  EXPECT_NEAR(pin.s.finger_deflection_m.x(), -3e-6, 1e-15) << "the tips held at the wall";
  EXPECT_NEAR(pin.s.part_m.x(), 2e-3 + 10e-6, 1e-15);
  EXPECT_EQ(pin.s.offset_m.x(), offset) << "no slip";
  // A steady press is a steady force (the stage still).
  out = hold(pin.w, pin.s, pin.g, Pin::closed, 0.05);
  EXPECT_NEAR(out.force_on_gripper_N.x(), -k2 * 3e-6, 1e-12);
  // Back to the middle: the fingers spring back, the pin where it was in them.
  out = move(pin.w, pin.s, pin.g, {2e-3, 0, 100e-6}, Pin::closed);
  EXPECT_EQ(out.force_on_gripper_N.x(), 0.0);
  EXPECT_EQ(pin.s.finger_deflection_m.norm(), 0.0);
  EXPECT_NEAR(pin.s.part_m.x(), 2e-3 + offset, 1e-15);
  // Turned by 90 degrees the fingers close along y: pushed along x (across them), the pin slips at
  // once (their width is stiff), and they do not bend.
  move(pin.w, pin.s, pin.g, {2e-3, 0, 550e-6}, Pin::closed);
  move(pin.w, pin.s, pin.g, {2e-3, 0, 550e-6}, Pin::closed, M_PI / 2);
  move(pin.w, pin.s, pin.g, {2e-3, 0, 100e-6}, Pin::closed, M_PI / 2);
  ASSERT_TRUE(pin.w.inserted(pin.s));
  out = move(pin.w, pin.s, pin.g, {2e-3 + 13e-6, 0, 100e-6}, Pin::closed, M_PI / 2);
  EXPECT_LT(std::abs(pin.s.finger_deflection_m.x()), 1e-9);
  EXPECT_LT(std::abs(pin.s.finger_deflection_m.y()), 1e-12);
}

TEST(PinInHole, TheHoleMustLeaveClearanceAndHoldThePinAboveTheSubstrate) {
  PickPlaceParams p = pin_in_hole_scene();
  p.hole_side_m = p.part_side_m;
  EXPECT_THROW(PickPlaceWorld{p}, InvalidParams);
  p = pin_in_hole_scene();
  p.hole_depth_m = p.part_height_m;
  EXPECT_THROW(PickPlaceWorld{p}, InvalidParams);
  EXPECT_NEAR(pin_in_hole_scene().part_weight_N(), 8500 * 200e-6 * 200e-6 * 600e-6 * 9.81, 1e-15);
}

// Orientation: the fingers turned by `yaw` (the rotary axis), steps of 1 ms.
PickPlaceOutput turn(const PickPlaceWorld& w, PickPlaceState& s, const Eigen::Vector3d& at, double opening,
                     double from, double to) {
  PickPlaceOutput out;
  const int n = std::max(1, static_cast<int>(std::abs(to - from) / 1e-3));
  for (int i = 1; i <= n; ++i) out = w.step(s, at, opening, 1e-3, from + (to - from) * i / n);
  return out;
}

TEST(Orientation, ATurnedSquarePinFitsItsHoleOnlyWithinTheAngleTheClearanceLeaves) {
  const PickPlaceWorld w{pin_in_hole_scene()};  // 200 um in 220 um
  // s (cos d + sin d) <= 220 um: d <= 6.06 deg (and its images modulo 90 deg). In the hole the
  // pin's centre rests at 0 (its 600 um half down the 300 um bore), on the rim at 300 um.
  const double limit = std::asin(1.1 / std::sqrt(2.0)) - M_PI / 4, in = 0.0, rim = 300e-6;
  EXPECT_NEAR(limit * 180 / M_PI, 6.06, 0.01);
  EXPECT_NEAR(w.rest_z_m(2e-3, 0, limit - 1e-3), in, 1e-12);
  EXPECT_NEAR(w.rest_z_m(2e-3, 0, limit + 1e-3), rim, 1e-12);
  EXPECT_NEAR(w.rest_z_m(2e-3, 0, M_PI / 2 + 0.5 * limit), in, 1e-12) << "a square fits every quarter turn";
  EXPECT_NEAR(w.rest_z_m(2e-3, 0, -M_PI / 4), rim, 1e-12);
  // Turned by 3 deg it has 10 - 100 (cos + sin - 1) = 4.6 um of play left each side.
  const double d = 3 * M_PI / 180;
  EXPECT_NEAR(w.hole_play_m(d), 0.5 * (220e-6 - 200e-6 * (std::cos(d) + std::sin(d))), 1e-15);
  EXPECT_NEAR(w.rest_z_m(2e-3 + 4.5e-6, 0, d), in, 1e-12);
  EXPECT_NEAR(w.rest_z_m(2e-3 + 5.0e-6, 0, d), rim, 1e-12);
  // A hole turned by 30 deg takes the pin at 30 deg, in the hole's own frame.
  PickPlaceParams p = pin_in_hole_scene();
  p.hole_yaw_rad = M_PI / 6;
  const PickPlaceWorld turned{p};
  EXPECT_NEAR(turned.rest_z_m(2e-3, 0, 0.0), rim, 1e-12);
  EXPECT_NEAR(turned.rest_z_m(2e-3, 0, M_PI / 6), in, 1e-12);
  const Eigen::Vector2d along_side = 8e-6 * Eigen::Vector2d(std::cos(M_PI / 6), std::sin(M_PI / 6));
  EXPECT_NEAR(turned.rest_z_m(2e-3 + along_side.x(), along_side.y(), M_PI / 6), in, 1e-12);
  EXPECT_NEAR(turned.rest_z_m(2e-3 + 1.4 * along_side.x(), 1.4 * along_side.y(), M_PI / 6), rim, 1e-12);
}

TEST(Orientation, TheClosingFingersSquareThePinAndTurnItWithThemToItsHole) {
  PickPlaceParams p = pin_in_hole_scene();
  p.part_yaw_rad = 20 * M_PI / 180;  // on its tray, 20 deg off the fingers
  p.hole_yaw_rad = -35 * M_PI / 180;
  const PickPlaceWorld w{p};
  auto s = w.initial_state();
  Eigen::Vector3d g(0, 0, 1e-3);
  const double open = 400e-6, closed = 160e-6, align = 18 * M_PI / 180;
  turn(w, s, g, open, 0.0, align);
  move(w, s, g, {0, 0, 350e-6}, open, align);
  for (double t = 0; t < 0.1; t += 1e-3) w.step(s, g, closed, 1e-3, align);
  EXPECT_NEAR(s.part_yaw_rad, align, 1e-12) << "squeezed flat against the fingers (2 deg)";
  for (int i = 1; i <= 200; ++i) w.step(s, {0, 0, 350e-6 + i * 1e-6}, closed, 1e-3, align);
  g = {0, 0, 550e-6};
  ASSERT_EQ(s.phase, PartPhase::kGrasped);
  // Turned to the hole's orientation less a quarter turn: the square's symmetry.
  const double to = p.hole_yaw_rad;
  turn(w, s, g, closed, align, to);
  EXPECT_NEAR(s.part_yaw_rad, to, 1e-12);
  EXPECT_NEAR(w.orientation_error_rad(s), 0.0, 1e-12);
  EXPECT_NEAR(s.part_m.x(), 0.0, 1e-12) << "the tips' centre is the axis of rotation";
  move(w, s, g, {2e-3, 0, 550e-6}, closed, to);
  move(w, s, g, {2e-3, 0, 40e-6}, closed, to);
  EXPECT_TRUE(w.inserted(s));
  // Down in its hole, the walls keep its yaw: the fingers slip round it.
  turn(w, s, g, closed, to, to + 0.2);
  EXPECT_NEAR(s.part_yaw_rad, to, 1e-12);
}

TEST(Orientation, APinNotTurnedToItsHoleSitsOnTheRim) {
  PickPlaceParams p = pin_in_hole_scene();
  p.hole_yaw_rad = 10 * M_PI / 180;  // beyond the 6.1 deg the clearance allows
  const PickPlaceWorld w{p};
  auto s = w.initial_state();
  Eigen::Vector3d g(0, 0, 1e-3);
  move(w, s, g, {0, 0, 350e-6}, 400e-6);
  hold(w, s, g, 160e-6, 0.1);
  move(w, s, g, {0, 0, 550e-6}, 160e-6);
  move(w, s, g, {2e-3, 0, 550e-6}, 160e-6);
  const auto out = move(w, s, g, {2e-3, 0, 340e-6}, 160e-6);
  EXPECT_FALSE(w.inserted(s));
  EXPECT_NEAR(s.part_m.z(), 300e-6, 1e-12) << "on the rim";
  EXPECT_GT(out.force_on_gripper_N.z(), 0.0);
  EXPECT_NEAR(w.orientation_error_rad(s), -p.hole_yaw_rad, 1e-12);
}

}  // namespace
}  // namespace mc::microworld
