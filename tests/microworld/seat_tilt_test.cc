// A tilted seat (the substrate on the parallel positioner turned about a horizontal axis): a pin
// held upright goes into its hole only as deep as the two-point wedge lets it, and is placed only
// at the hole's bottom.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "microcobot/microworld/pick_place_world.h"

namespace mc::microworld {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// The pin-in-hole scene (a 200 um pin, 600 um tall, into a 220 um hole 300 um deep at x = 2 mm)
// with the seat tilted by `tilt` against the fingers' vertical.
struct TiltedPin {
  explicit TiltedPin(double tilt) : tilt_rad(tilt) {}
  PickPlaceWorld w{pin_in_hole_scene()};
  PickPlaceState s = w.initial_state();
  Eigen::Vector3d g{0, 0, 1e-3};
  double tilt_rad;
  static constexpr double open = 400e-6, closed = 160e-6;

  PickPlaceOutput move(const Eigen::Vector3d& to, double opening) {
    PickPlaceOutput out;
    const int n = std::max(1, static_cast<int>((to - g).norm() / 1e-6));
    const Eigen::Vector3d from = g;
    for (int i = 1; i <= n; ++i) {
      g = from + (to - from) * (static_cast<double>(i) / n);
      out = w.step(s, g, opening, 1e-3, 0.0, {}, tilt_rad);
    }
    return out;
  }
  void hold(double opening, double t) {
    for (double k = 0; k < t; k += 1e-3) w.step(s, g, opening, 1e-3, 0.0, {}, tilt_rad);
  }
  // Grasps the pin, carries it over the hole's centre and pushes it down as far as the fingers go
  // (their tips 40 um over the substrate), then lets go and lifts the fingers away.
  PickPlaceOutput insert() {
    move({0, 0, 350e-6}, open);
    hold(closed, 0.1);
    move({0, 0, 550e-6}, closed);
    EXPECT_EQ(s.phase, PartPhase::kGrasped);
    move({2e-3, 0, 550e-6}, closed);
    const PickPlaceOutput pressed = move({2e-3, 0, 40e-6}, closed);
    hold(open, 0.1);
    move({2e-3, 0, 1e-3}, open);
    return pressed;
  }
};

TEST(SeatTilt, TheEntryDepthIsTheHolesUntilThePinsLeanSpansItThenTheTwoPointWedge) {
  const PickPlaceWorld w{pin_in_hole_scene()};
  EXPECT_DOUBLE_EQ(w.hole_entry_depth_m(0.0, 0.0), 300e-6);
  // l sin(theta) + w cos(theta) = D, written out for 200 um in 220 um.
  const auto wedge_m = [](double theta) { return (220e-6 - 200e-6 * std::cos(theta)) / std::sin(theta); };
  EXPECT_GT(wedge_m(3 * kDeg), 300e-6);
  EXPECT_DOUBLE_EQ(w.hole_entry_depth_m(0.0, 3 * kDeg), 300e-6) << "a 3 deg lean still reaches the bottom";
  EXPECT_NEAR(w.hole_entry_depth_m(0.0, 6 * kDeg), wedge_m(6 * kDeg), 1e-12);
  EXPECT_NEAR(w.hole_entry_depth_m(0.0, -6 * kDeg), wedge_m(6 * kDeg), 1e-12) << "either way";
  EXPECT_NEAR(w.hole_entry_depth_m(0.0, 20 * kDeg), wedge_m(20 * kDeg), 1e-12);
  EXPECT_LT(w.hole_entry_depth_m(0.0, 20 * kDeg), w.hole_entry_depth_m(0.0, 6 * kDeg))
      << "steeper, shallower";
  // A pin turned beyond what the clearance takes does not go in at any tilt.
  EXPECT_EQ(w.hole_entry_depth_m(10 * kDeg, 0.0), 0.0);
  EXPECT_EQ(w.hole_entry_depth_m(10 * kDeg, 6 * kDeg), 0.0);
  // The rest height follows: the pin's centre half its height over the wedge's depth.
  EXPECT_NEAR(w.rest_z_m(2e-3, 0.0, 0.0, 6 * kDeg), 300e-6 - wedge_m(6 * kDeg), 1e-12);
}

TEST(SeatTilt, APinPushedIntoATiltedHoleWedgesThereTheFingersFeelItAndItIsNotPlaced) {
  TiltedPin tilted(6 * kDeg);
  const PickPlaceOutput pressed = tilted.insert();
  const double depth = tilted.w.hole_entry_depth_m(0.0, 6 * kDeg);
  ASSERT_LT(depth, 250e-6);
  EXPECT_NEAR(tilted.s.part_m.z(), 300e-6 - depth, 1e-12) << "stopped where it wedged";
  EXPECT_GT(pressed.force_on_gripper_N.z(), 0.0) << "the wedge pushes back on the fingers";
  EXPECT_EQ(tilted.s.phase, PartPhase::kOnSubstrate);
  EXPECT_TRUE(tilted.w.inserted(tilted.s)) << "partly in: the walls hold it";
  EXPECT_FALSE(tilted.w.placed(tilted.s)) << "not at the bottom";
  EXPECT_FALSE(tilted.s.crashed);
  // The same insertion with the seat levelled to within the clearance's tolerance goes down.
  TiltedPin level(0.5 * kDeg);
  level.insert();
  EXPECT_NEAR(level.s.part_m.z(), 0.0, 1e-12);
  EXPECT_TRUE(level.w.placed(level.s));
  EXPECT_DOUBLE_EQ(level.s.seat_tilt_rad, 0.5 * kDeg);
}

}  // namespace
}  // namespace mc::microworld
