#include "microcobot/cell/assembly_batch.h"

#include <cmath>
#include <random>

#include <fmt/format.h>

#include "microcobot/core/error.h"

namespace mc::cell {

void AssemblyBatchParams::validate() const {
  require(parts >= 1 && parts <= 10000, "parts", "must be within [1, 10000]", parts);
  require(seed >= 0, "seed", "must be >= 0", seed);
  require_positive(min_side_m, "min_side_m");
  require(max_side_m >= min_side_m, "max_side_m", "must be at least min_side_m", max_side_m);
  require(part_height_m > hole_depth_m + 100e-6, "part_height_m",
          "must stand at least 100 um above a full bore (hole_depth_m) to be held", part_height_m);
  require_positive(min_clearance_m, "min_clearance_m");
  require(max_clearance_m >= min_clearance_m, "max_clearance_m", "must be at least min_clearance_m",
          max_clearance_m);
  require_positive(hole_depth_m, "hole_depth_m");
  require_non_negative(slot_error_m, "slot_error_m");
  // A pin off its slot by more than a quarter of its side along y is no longer between the
  // fingers' flats (microworld: |dy| < side / 2): 4 sigma must stay within it.
  require(4.0 * slot_error_m < 0.25 * min_side_m, "slot_error_m", "must be below min_side_m / 16",
          slot_error_m);
  // The open fingers must pass around the pin with its slot error on either side.
  require(max_side_m + 8.0 * slot_error_m < world.gripper.max_opening_m, "max_side_m",
          "must leave the open gripper (world.gripper.max_opening_m) 4 slot errors each side", max_side_m);
  require(std::isfinite(max_yaw_rad) && max_yaw_rad >= 0.0 && max_yaw_rad <= M_PI / 4 + 1e-12, "max_yaw_rad",
          "must be within [0, pi/4] rad (a square's orientations)", max_yaw_rad);
  require(std::isfinite(slot_yaw_error_rad) && slot_yaw_error_rad >= 0.0 && slot_yaw_error_rad <= 0.1,
          "slot_yaw_error_rad", "must be within [0, 0.1] rad", slot_yaw_error_rad);
  require_positive(half_size_m, "half_size_m");
  for (const auto& [key, v] : {std::pair{"tray_x_m", tray_x_m}, std::pair{"tray_y_m", tray_y_m},
                               std::pair{"plate_x_m", plate_x_m}, std::pair{"plate_y_m", plate_y_m}})
    require(std::isfinite(v) && std::abs(v) + half_size_m <= 4e-3, key,
            "must keep the area (half_size_m) within 4 mm of the stage's home", v);
  require(std::isfinite(flat_fraction) && flat_fraction >= 0.0 && flat_fraction <= 1.0, "flat_fraction",
          "must be within [0, 1]", flat_fraction);
  require_positive(flat_side_m, "flat_side_m");
  require(flat_side_m + 8.0 * slot_error_m < world.gripper.max_opening_m, "flat_side_m",
          "must leave the open gripper (world.gripper.max_opening_m) 4 slot errors each side", flat_side_m);
  require(4.0 * slot_error_m < 0.25 * flat_side_m, "slot_error_m", "must be below flat_side_m / 16",
          slot_error_m);
  require(
      std::isfinite(flat_thickness_m) && 0.5 * flat_thickness_m >= world.min_tip_height_m &&
          flat_thickness_m < flat_side_m,
      "flat_thickness_m",
      "must be below flat_side_m and at least twice world.min_tip_height_m (the tips grasp at half of it)",
      flat_thickness_m);
  require(std::isfinite(seat_tolerance_m) && seat_tolerance_m > 0.0 && seat_tolerance_m <= 1e-3,
          "seat_tolerance_m", "must be within (0, 1 mm]", seat_tolerance_m);
  require_non_negative(flat_finger_pulloff_N, "flat_finger_pulloff_N");
  require_non_negative(flat_seat_min_pulloff_N, "flat_seat_min_pulloff_N");
  require(std::isfinite(flat_seat_max_pulloff_N) && flat_seat_max_pulloff_N >= flat_seat_min_pulloff_N,
          "flat_seat_max_pulloff_N", "must be at least flat_seat_min_pulloff_N", flat_seat_max_pulloff_N);
  require(std::isfinite(bore_error_m) && bore_error_m >= 0.0 && bore_error_m <= 100e-6, "bore_error_m",
          "must be within [0, 100 um]", bore_error_m);
  require(layout == "random" || layout == "grid", "layout", "must be random or grid (got '" + layout + "')");
  if (layout == "grid") {
    // The open gripper round one part must clear the next: the fingers' reach (half the opening plus
    // their thickness, to its corner) plus a neighbour's half-diagonal, plus 4 slot errors of each.
    const auto& g = world.gripper;
    const double reach = std::hypot(0.5 * g.max_opening_m + g.finger_thickness_m, 0.5 * g.finger_width_m);
    const double widest = std::max(max_side_m, flat_fraction > 0.0 ? flat_side_m : 0.0);
    const double need = reach + widest / std::sqrt(2.0) + 8.0 * slot_error_m;
    require(std::isfinite(grid_pitch_m) && grid_pitch_m >= need, "grid_pitch_m",
            fmt::format("must be at least {:.0f} um: the open fingers' reach round a part plus a neighbour's "
                        "half-diagonal and 8 slot errors",
                        need * 1e6),
            grid_pitch_m);
    const int n = grid_cells_per_side(half_size_m, grid_pitch_m);
    require(
        n * n - 1 <= microworld::PickPlaceParams::kMaxNeighbours, "grid_pitch_m",
        fmt::format("makes a load of {} x {} parts within half_size_m: a scene holds at most {} neighbours",
                    n, n, microworld::PickPlaceParams::kMaxNeighbours),
        grid_pitch_m);
  }
  microworld::ReleaseStrategy r;
  require(release == "auto" || microworld::parse_release(release, r), "release",
          "must be auto, open, shake or roll (got '" + release + "')");
  require(std::isfinite(min_release_margin) && min_release_margin >= 1.0 && min_release_margin <= 100.0,
          "min_release_margin", "must be within [1, 100]", min_release_margin);
  require(std::isfinite(max_tip_misalignment_m) && max_tip_misalignment_m >= 0.0 &&
              max_tip_misalignment_m <= 40e-6,
          "max_tip_misalignment_m", "must be within [0, 40] um (the tip faces' height is 50 um)",
          max_tip_misalignment_m);
  require(std::isfinite(max_seat_tilt_rad) && max_seat_tilt_rad >= 0.0 && max_seat_tilt_rad <= 0.07,
          "max_seat_tilt_rad", "must be within [0, 0.07] rad (4 deg)", max_seat_tilt_rad);
  world.validate();
}

microworld::ReleaseStrategy choose_release(const microworld::PickPlaceParams& world, bool in_bore,
                                           const std::string& release, double min_margin, double& margin) {
  using microworld::ReleaseStrategy;
  ReleaseStrategy chosen = ReleaseStrategy::kOpen;
  if (release != "auto") {
    require(microworld::parse_release(release, chosen), "release",
            "must be auto, open, shake or roll (got '" + release + "')");
    margin = microworld::release_margin(world, chosen, in_bore);
    return chosen;
  }
  // The least disturbing first: opening alone, then a turn of the fingers, then the burst.
  margin = -1.0;
  for (ReleaseStrategy r : {ReleaseStrategy::kOpen, ReleaseStrategy::kRoll, ReleaseStrategy::kShake}) {
    const double m = microworld::release_margin(world, r, in_bore);
    if (m >= min_margin) {
      margin = m;
      return r;
    }
    if (m > margin) {
      margin = m;
      chosen = r;
    }
  }
  return chosen;
}

int grid_cells_per_side(double half_size_m, double pitch_m) noexcept {
  if (!(pitch_m > 0.0) || !(half_size_m >= 0.0)) return 0;
  return 1 + static_cast<int>(std::floor(2.0 * half_size_m / pitch_m + 1e-9));
}

namespace {

// A grid cell's offset from its area's centre (cells row by row, the grid centred).
Eigen::Vector2d grid_offset(int cell, int n, double pitch_m) {
  const double c = 0.5 * (n - 1);
  return {(cell % n - c) * pitch_m, (cell / n - c) * pitch_m};
}

// A part as its neighbours see it: standing in its slot, or placed (on its seat, or in its bore).
microworld::NeighbourPart standing(const AssemblyJob& j, bool placed) {
  microworld::NeighbourPart n;
  n.side_m = j.world.part_side_m;
  if (placed) {
    n.xy_m = j.world.target_m.head<2>();  // where its bore really is
    n.yaw_rad = j.target_yaw_rad;
    n.top_z_m = j.world.height_m() - j.world.hole_depth_m;
  } else {
    n.xy_m = j.world.part_start_m.head<2>();
    n.yaw_rad = j.world.part_yaw_rad;
    n.top_z_m = j.world.height_m();
  }
  return n;
}

}  // namespace

std::vector<AssemblyJob> assembly_jobs(const AssemblyBatchParams& params) {
  params.validate();
  std::mt19937_64 rng(static_cast<std::uint64_t>(params.seed));
  std::uniform_real_distribution<double> side(params.min_side_m, params.max_side_m);
  std::uniform_real_distribution<double> clearance(params.min_clearance_m, params.max_clearance_m);
  std::uniform_real_distribution<double> area(-params.half_size_m, params.half_size_m);
  std::normal_distribution<double> slot(0.0, 1.0);
  // The orientations from a stream of their own: the positions are those of the same seed without.
  std::mt19937_64 yaw_rng(static_cast<std::uint64_t>(params.seed) * 0x9E3779B97F4A7C15ULL + 0x796177ULL);
  std::uniform_real_distribution<double> yaw(-1.0, 1.0);
  std::normal_distribution<double> slot_yaw(0.0, 1.0);
  std::mt19937_64 flat_rng(static_cast<std::uint64_t>(params.seed) * 0xD1B54A32D192ED03ULL + 0x666c6174ULL);
  std::uniform_real_distribution<double> flat_u(0.0, 1.0);
  std::uniform_real_distribution<double> seat_pulloff(params.flat_seat_min_pulloff_N,
                                                      params.flat_seat_max_pulloff_N);
  // The bores' errors from a stream of their own: without them, the batch is the one of before.
  std::mt19937_64 bore_rng(static_cast<std::uint64_t>(params.seed) * 0xA24BAED4963EE407ULL + 0x626f7265ULL);
  std::normal_distribution<double> bore(0.0, 1.0);
  // The seats' tilts from a stream of their own: without them, the batch is the one of before.
  std::mt19937_64 tilt_rng(static_cast<std::uint64_t>(params.seed) * 0x9FB21C651E98DF25ULL + 0x74696c74ULL);
  std::uniform_real_distribution<double> tilt_u(0.0, 1.0);
  // The tips' misalignments from a stream of their own likewise.
  std::mt19937_64 tips_rng(static_cast<std::uint64_t>(params.seed) * 0xE7037ED1A0B428DBULL + 0x74697073ULL);
  std::uniform_real_distribution<double> tips_u(-1.0, 1.0);
  const bool grid = params.layout == "grid";
  const int per_side = grid ? grid_cells_per_side(params.half_size_m, params.grid_pitch_m) : 1;
  const int per_load = per_side * per_side;
  std::vector<AssemblyJob> jobs;
  jobs.reserve(static_cast<std::size_t>(params.parts));
  for (int i = 0; i < params.parts; ++i) {
    AssemblyJob j;
    j.index = i;
    j.side_m = side(rng);
    j.clearance_m = clearance(rng);
    j.nominal_part_m = {params.tray_x_m + area(rng), params.tray_y_m + area(rng)};
    j.target_m = {params.plate_x_m + area(rng), params.plate_y_m + area(rng)};
    if (grid) {  // the same draws, the places on the grids
      const Eigen::Vector2d cell = grid_offset(i % per_load, per_side, params.grid_pitch_m);
      j.nominal_part_m = Eigen::Vector2d(params.tray_x_m, params.tray_y_m) + cell;
      j.target_m = Eigen::Vector2d(params.plate_x_m, params.plate_y_m) + cell;
    }
    const Eigen::Vector2d error(params.slot_error_m * slot(rng), params.slot_error_m * slot(rng));
    j.world = params.world;
    j.world.part_side_m = j.side_m;
    j.world.part_height_m = params.part_height_m;
    j.world.hole_side_m = j.side_m + 2.0 * j.clearance_m;
    j.world.hole_depth_m = params.hole_depth_m;
    j.world.part_start_m = {j.nominal_part_m.x() + error.x(), j.nominal_part_m.y() + error.y(), 0.0};
    const Eigen::Vector2d bore_error(params.bore_error_m * bore(bore_rng),
                                     params.bore_error_m * bore(bore_rng));
    j.world.target_m = {j.target_m.x() + bore_error.x(), j.target_m.y() + bore_error.y(), 0.0};
    if (params.max_tip_misalignment_m > 0.0)
      j.world.gripper.tip_misalignment_m = params.max_tip_misalignment_m * tips_u(tips_rng);
    if (params.max_seat_tilt_rad > 0.0) {  // a tilt up to the largest, about a horizontal axis drawn uniform
      const double tilt = params.max_seat_tilt_rad * tilt_u(tilt_rng), axis = 2.0 * M_PI * tilt_u(tilt_rng);
      j.world.seat_tilt_x_rad = tilt * std::cos(axis);
      j.world.seat_tilt_y_rad = tilt * std::sin(axis);
    }
    j.nominal_part_yaw_rad = params.max_yaw_rad * yaw(yaw_rng);
    j.target_yaw_rad = params.max_yaw_rad * yaw(yaw_rng);
    j.world.part_yaw_rad = j.nominal_part_yaw_rad + params.slot_yaw_error_rad * slot_yaw(yaw_rng);
    j.world.hole_yaw_rad = j.target_yaw_rad;
    // Flat parts from a stream of their own: without any, the batch is the one of before.
    const bool flat = flat_u(flat_rng) < params.flat_fraction;
    const double pulloff = seat_pulloff(flat_rng);  // drawn for every part: each seat's finish is its own
    if (flat) {
      j.flat = true;
      j.side_m = params.flat_side_m;
      j.clearance_m = params.seat_tolerance_m;
      j.world.part_side_m = params.flat_side_m;
      j.world.part_height_m = params.flat_thickness_m;
      j.world.hole_side_m = 0.0;
      j.world.hole_depth_m = 0.0;
      j.world.seat_tolerance_m = params.seat_tolerance_m;
      j.world.finger_pulloff_N = params.flat_finger_pulloff_N;
      j.world.substrate_pulloff_N = pulloff;
    }
    j.release = choose_release(j.world, !j.flat, params.release, params.min_release_margin, j.release_margin);
    jobs.push_back(j);
  }
  if (grid) {
    // Each part's scene holds the rest of its load: the later parts in their slots, the earlier
    // ones placed (a load's n^2 - 1 others; n^2 <= 9 keeps them within kMaxNeighbours).
    for (AssemblyJob& j : jobs) {
      const int load = j.index / per_load;
      const int first = load * per_load, end = std::min(first + per_load, params.parts);
      auto& w = j.world;
      w.neighbour_count = 0;
      for (int k = first; k < end; ++k) {
        if (k == j.index || w.neighbour_count >= microworld::PickPlaceParams::kMaxNeighbours) continue;
        w.neighbours[static_cast<std::size_t>(w.neighbour_count++)] =
            standing(jobs[static_cast<std::size_t>(k)], k < j.index);
      }
    }
  }
  for (AssemblyJob& j : jobs) j.world.validate();
  return jobs;
}

}  // namespace mc::cell
