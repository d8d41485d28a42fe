// A pick-and-place by the visual servo alone, the XY encoders off: the part
// placed within 1 um of its target and every axis holding at the end, on starts and targets of the
// validation draw (the sequence was set up on `vision pick-place --set-seed 1`) and on a scene it
// was not set up on (scenes/small-part.yaml's 200 um cube); a sequence that cannot finish stops
// holding; bad parameters are refused.

#include <filesystem>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/studies/visual_pick_place_run.h"

namespace mc::studies {
namespace visual_pick_place_test {

VisualPickPlaceParams pick_place_case(const Eigen::Vector2d& target_um, const Eigen::Vector2d& start_um,
                                      std::uint64_t seed) {
  VisualPickPlaceParams p;
  p.width_px = p.height_px = 768;  // 814 um at 5x: the part, its target and the tips in view
  p.target_offset_m = 1e-6 * target_um;
  p.start_offset_m = 1e-6 * start_um;
  p.seed = seed;
  return p;
}

void expect_placed(const VisualPickPlaceResult& r, const std::string& what) {
  EXPECT_TRUE(r.completed) << what << ": stopped in " << to_string(r.failed_phase);
  EXPECT_TRUE(r.part_on_substrate) << what;
  EXPECT_LE(r.placement_error_m.norm(), 1e-6) << what;
  EXPECT_TRUE(r.xy_holding) << what;
  EXPECT_TRUE(r.z_holding) << what;
  EXPECT_TRUE(r.gripper_holding) << what;
  // The part did travel: it was picked up and carried, not left where it was.
  bool grasped = false, carried = false;
  for (const PickPlaceFrame& f : r.frames) {
    grasped = grasped || f.grip_force_N > 0.0;
    carried = carried ||
              (f.phase == PickPlacePhase::kTransport && f.part_m.z() > r.frames.front().part_m.z() + 20e-6);
  }
  EXPECT_TRUE(grasped) << what;
  EXPECT_TRUE(carried) << what;
}

TEST(VisualPickPlace, PlacesThePartWithin1umEncodersOff) {
  expect_placed(run_visual_pick_place(pick_place_case({-450.0, 60.0}, {80.0, 290.0}, 2001)),
                "300 um cube, -x");
  expect_placed(run_visual_pick_place(pick_place_case({420.0, -85.0}, {110.0, 260.0}, 2002)),
                "300 um cube, +x");
}

TEST(VisualPickPlace, PlacesASmallerPartOfAnotherScene) {
  VisualPickPlaceParams p = pick_place_case({430.0, 40.0}, {120.0, 270.0}, 3001);
  p.scene = std::string(MC_SOURCE_DIR) + "/scenes/small-part.yaml";
  expect_placed(run_visual_pick_place(p), "200 um part");
}

TEST(VisualPickPlace, ASequenceThatCannotFinishStopsHolding) {
  VisualPickPlaceParams p = pick_place_case({-450.0, 60.0}, {80.0, 290.0}, 2001);
  p.phase_frames = 10;  // 300 um in 10 frames: beyond the stage's speed
  const VisualPickPlaceResult r = run_visual_pick_place(p);
  EXPECT_FALSE(r.completed);
  EXPECT_EQ(r.failed_phase, PickPlacePhase::kApproach);
  EXPECT_TRUE(r.xy_holding);
  EXPECT_TRUE(r.z_holding);
  EXPECT_TRUE(r.gripper_holding);
  EXPECT_LT(r.frames.back().part_m.head<2>().norm(), 1e-12);  // the part untouched
}

TEST(VisualPickPlace, BadParametersAreRefused) {
  VisualPickPlaceParams p = pick_place_case({-450.0, 60.0}, {80.0, 290.0}, 1);
  p.servo.gain_per_s = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(run_visual_pick_place(p), InvalidParams);
  p = pick_place_case({-450.0, 60.0}, {80.0, 290.0}, 1);
  p.approach_opening_m = 250e-6;  // narrower than the 300 um part
  EXPECT_THROW(run_visual_pick_place(p), InvalidParams);
  p = pick_place_case({2000.0, 0.0}, {80.0, 290.0}, 1);  // the target outside the field
  EXPECT_THROW(run_visual_pick_place(p), InvalidInput);
  p = pick_place_case({-450.0, 60.0}, {80.0, 290.0}, 1);
  p.scene = "pin-in-hole";  // an insertion, not a placement
  EXPECT_THROW(run_visual_pick_place(p), InvalidInput);
}

}  // namespace visual_pick_place_test
}  // namespace mc::studies
