// The batch of insertions: seeded, within its ranges, the pins off their
// slots by what the robot is not told, and bad scenes refused with the key named.
#include "microcobot/cell/assembly_batch.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "microcobot/core/error.h"
#include "microcobot/core/params.h"

namespace mc::cell {
namespace {

TEST(AssemblyBatch, TheSameSeedGivesTheSameBatchWithinItsRanges) {
  AssemblyBatchParams p;
  p.parts = 200;
  p.seed = 29;
  const auto a = assembly_jobs(p), b = assembly_jobs(p);
  ASSERT_EQ(a.size(), 200u);
  double sum_sq = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].world.part_start_m, b[i].world.part_start_m);
    EXPECT_EQ(a[i].side_m, b[i].side_m);
    EXPECT_GE(a[i].side_m, p.min_side_m);
    EXPECT_LE(a[i].side_m, p.max_side_m);
    EXPECT_GE(a[i].clearance_m, p.min_clearance_m);
    EXPECT_LE(a[i].clearance_m, p.max_clearance_m);
    EXPECT_NEAR(a[i].world.hole_side_m - a[i].world.part_side_m, 2.0 * a[i].clearance_m, 1e-15);
    EXPECT_LE(std::abs(a[i].nominal_part_m.x() - p.tray_x_m), p.half_size_m);
    EXPECT_LE(std::abs(a[i].target_m.y() - p.plate_y_m), p.half_size_m);
    EXPECT_EQ(a[i].world.target_m.head<2>(), a[i].target_m) << "the bores are where the cell is told";
    sum_sq += (a[i].world.part_start_m.head<2>() - a[i].nominal_part_m).squaredNorm();
  }
  // The slot error: sigma per axis as asked (400 draws: within 15 %).
  EXPECT_NEAR(std::sqrt(sum_sq / (2.0 * a.size())), p.slot_error_m, 0.15 * p.slot_error_m);
  p.seed = 30;
  EXPECT_NE(assembly_jobs(p)[0].side_m, a[0].side_m);
}

TEST(AssemblyBatch, BadScenesAreRefusedWithTheKeyNamed) {
  const auto refused = [](const std::string& yaml, const std::string& key) {
    try {
      (void)assembly_jobs(params_from_yaml_text<AssemblyBatchParams>(yaml));
      ADD_FAILURE() << yaml << ": accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  refused("parts: 0", "parts");
  refused("max_side_m: 590.0e-6", "max_side_m");  // the open gripper is 600 um
  refused("min_clearance_m: 10.0e-6\nmax_clearance_m: 5.0e-6", "max_clearance_m");
  refused("slot_error_m: 10.0e-6", "slot_error_m");     // 4 sigma beyond a 100 um pin's flats
  refused("part_height_m: 350.0e-6", "part_height_m");  // nothing to hold above a 300 um bore
  refused("plate_x_m: 3.9e-3", "plate_x_m");            // beyond the stage's reach
  refused("bore_depth: 1", "bore_depth");               // an unknown key
  refused("world:\n  finger_friction: -1", "finger_friction");
  refused("flat_fraction: 1.5", "flat_fraction");
  refused("release: wiggle", "release");
  refused("flat_thickness_m: 10.0e-6", "flat_thickness_m");  // the tips may not go below 10 um
  refused("flat_seat_min_pulloff_N: 5.0e-5\nflat_seat_max_pulloff_N: 1.0e-5", "flat_seat_max_pulloff_N");
  refused("min_release_margin: 0.5", "min_release_margin");
  refused("layout: spiral", "layout");
  refused("bore_error_m: 1.0e-3", "bore_error_m");
  refused("layout: grid\ngrid_pitch_m: 500.0e-6", "grid_pitch_m");  // the open fingers reach 350 um
  refused("layout: grid\ngrid_pitch_m: 610.0e-6\nhalf_size_m: 1.0e-3", "grid_pitch_m");  // 4 x 4 a load
}

// The plate's errors (bore_error_m) move each bore from its drawing, from a stream of their own:
// the drawing (what the cell is told) and everything else are the batch's without them.
TEST(AssemblyBatch, BoreErrorsMoveTheBoresFromTheirDrawingAndNothingElse) {
  AssemblyBatchParams p;
  p.parts = 400;
  p.seed = 71;
  const std::vector<AssemblyJob> exact = assembly_jobs(p);
  p.bore_error_m = 10e-6;
  const std::vector<AssemblyJob> off = assembly_jobs(p);
  double sum_sq = 0.0;
  for (std::size_t i = 0; i < off.size(); ++i) {
    EXPECT_EQ(exact[i].target_m, off[i].target_m) << "the drawing";
    EXPECT_EQ(exact[i].world.target_m.head<2>(), exact[i].target_m) << "without errors, the bore is drawn";
    EXPECT_EQ(exact[i].world.part_start_m, off[i].world.part_start_m);
    EXPECT_EQ(exact[i].side_m, off[i].side_m);
    sum_sq += (off[i].world.target_m.head<2>() - off[i].target_m).squaredNorm();
  }
  // Two axes of 10 um each: an rms of 14.1 um over 400 bores, within 10 % (5 sigma of its spread).
  EXPECT_NEAR(std::sqrt(sum_sq / off.size()), std::sqrt(2.0) * 10e-6, 1.4e-6);
}

TEST(AssemblyBatch, OnAGridEachPartsSceneHoldsTheRestOfItsLoadInTheTrayOrPlaced) {
  AssemblyBatchParams p;
  p.parts = 10;
  p.seed = 37;
  p.layout = "grid";
  const auto jobs = assembly_jobs(p);
  ASSERT_EQ(grid_cells_per_side(p.half_size_m, p.grid_pitch_m), 3);
  for (const auto& j : jobs) {
    // On the grids: the slot's nominal place and the bore on grid points 700 um apart.
    const Eigen::Vector2d cell = j.nominal_part_m - Eigen::Vector2d(p.tray_x_m, p.tray_y_m);
    EXPECT_NEAR(std::remainder(cell.x(), p.grid_pitch_m), 0.0, 1e-12);
    EXPECT_NEAR(std::remainder(cell.y(), p.grid_pitch_m), 0.0, 1e-12);
    EXPECT_LT((j.target_m - Eigen::Vector2d(p.plate_x_m, p.plate_y_m) - cell).norm(), 1e-12);
  }
  // Part 4, the grid's middle: 4 placed before it, 4 still in the tray after it.
  const auto& w = jobs[4].world;
  ASSERT_EQ(w.neighbour_count, 8);
  int placed = 0;
  for (int i = 0; i < w.neighbour_count; ++i) {
    const auto& n = w.neighbours[static_cast<std::size_t>(i)];
    const bool on_plate = (n.xy_m - Eigen::Vector2d(p.plate_x_m, p.plate_y_m)).norm() < 1.2e-3;
    placed += on_plate ? 1 : 0;
    EXPECT_NEAR(n.top_z_m, on_plate ? p.part_height_m - p.hole_depth_m : p.part_height_m, 1e-15);
    // Nothing of a neighbour within the open fingers' reach round this part's slot.
    EXPECT_GT((n.xy_m - jobs[4].world.part_start_m.head<2>()).norm(), 350e-6 + n.side_m / std::sqrt(2.0));
  }
  EXPECT_EQ(placed, 4);
  EXPECT_EQ(jobs[9].world.neighbour_count, 0) << "the tenth part begins a new load, alone";
  // The random layout is the batch of before: nobody else in a scene.
  p.layout = "random";
  for (const auto& j : assembly_jobs(p)) EXPECT_EQ(j.world.neighbour_count, 0);
}

TEST(AssemblyBatch, FlatPartsComeFromTheirOwnStreamAndEachGetsTheReleaseItsAdhesionNeeds) {
  AssemblyBatchParams pins;
  pins.parts = 100;
  pins.seed = 31;
  AssemblyBatchParams mixed = pins;
  mixed.flat_fraction = 0.5;
  const auto a = assembly_jobs(pins), b = assembly_jobs(mixed);
  int flats = 0;
  int chosen[3] = {0, 0, 0};
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_FALSE(a[i].flat);
    EXPECT_EQ(a[i].release, microworld::ReleaseStrategy::kOpen) << "a pin in its bore lets go when opened";
    EXPECT_EQ(a[i].world.part_start_m, b[i].world.part_start_m) << "the positions do not depend on the kinds";
    if (!b[i].flat) {
      EXPECT_EQ(a[i].side_m, b[i].side_m);
      continue;
    }
    ++flats;
    const auto& w = b[i].world;
    EXPECT_EQ(w.hole_side_m, 0.0);
    EXPECT_EQ(w.part_side_m, mixed.flat_side_m);
    EXPECT_EQ(w.part_height_m, mixed.flat_thickness_m);
    EXPECT_GE(w.substrate_pulloff_N, mixed.flat_seat_min_pulloff_N);
    EXPECT_LE(w.substrate_pulloff_N, mixed.flat_seat_max_pulloff_N);
    // auto: the first of open, roll, shake that reaches the margin; the ones before it do not.
    const auto r = b[i].release;
    ++chosen[static_cast<int>(r)];
    EXPECT_GE(b[i].release_margin, mixed.min_release_margin);
    EXPECT_DOUBLE_EQ(b[i].release_margin, microworld::release_margin(w, r, false));
    if (r != microworld::ReleaseStrategy::kOpen) {
      EXPECT_LT(microworld::release_margin(w, microworld::ReleaseStrategy::kOpen, false),
                mixed.min_release_margin);
    }
    if (r == microworld::ReleaseStrategy::kShake) {
      EXPECT_LT(microworld::release_margin(w, microworld::ReleaseStrategy::kRoll, false),
                mixed.min_release_margin);
    }
  }
  EXPECT_GT(flats, 35);
  EXPECT_LT(flats, 65);
  // Seats of 5-60 uN: every strategy has its parts (open above 40 uN, roll above ~11 uN).
  for (int c : chosen) EXPECT_GT(c, 0);
  mixed.release = "shake";
  for (const auto& j : assembly_jobs(mixed)) EXPECT_EQ(j.release, microworld::ReleaseStrategy::kShake);
}

}  // namespace
}  // namespace mc::cell
