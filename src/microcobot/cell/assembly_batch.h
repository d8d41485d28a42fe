#pragma once
/// @file
/// A small batch of watchmaking-like insertions (issue #29 point 1): N square pins taken from a
/// tray and inserted into the bores of an assembly plate. Each pin has its own side (100-300 um),
/// each bore its own radial clearance (3-20 um), drawn from a seeded generator; the pins sit in
/// their tray slots with a position error (the slot's play) that the cell does not know: the
/// robot is told each slot's nominal position and each bore's, as a fixtured tray and plate
/// would give them, and must cope with the rest (the closing fingers centre the pin along x; y is
/// found by a force-guarded search, assembly_task.h). Each slot and each bore has its own
/// orientation (issue #29 point 1), uniform within +-max_yaw_rad (+-45 deg: any orientation of a
/// square), told to the cell; a pin sits in its slot turned by a further error it is not told (the
/// grasp's squeeze takes it out). The orientations come from their own stream of the seed: with
/// max_yaw_rad 0 and slot_yaw_error_rad 0 a batch is the one of before the rotary axis.
///
/// One job is one part: its microworld (microworld::PickPlaceParams: the pin, the bore, the
/// adhesion of the default 300 um scene) and what the cell is told. The cycles of a batch run one
/// after another on a fresh platform each (cell_run.h), so neighbouring parts do not interact yet.
/// Positions are world coordinates (the substrate's top at z = 0); SI units.

#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Dense>

#include "microcobot/microworld/pick_place_world.h"

namespace mc::cell {

struct AssemblyBatchParams {
  int parts = 10;              ///< pins in the batch, [1, 10000]
  int seed = 1;                ///< the generator's seed: the same seed gives the same batch
  double min_side_m = 100e-6;  ///< pin side, uniform in [min, max] (issue #29: 100-300 um)
  double max_side_m = 300e-6;
  double part_height_m = 600e-6;       ///< every pin's height
  double min_clearance_m = 3e-6;       ///< radial clearance of the bores, uniform in [min, max]
  double max_clearance_m = 20e-6;      ///< (issue #29: 3-20 um)
  double hole_depth_m = 300e-6;        ///< the bores' depth
  double slot_error_m = 5e-6;          ///< standard deviation of a pin in its slot (x and y)
  double max_yaw_rad = M_PI / 4;       ///< slots' and bores' orientations, uniform in [-max, max]
  double slot_yaw_error_rad = 0.0175;  ///< standard deviation of a pin's yaw in its slot (1 deg)
  double tray_x_m = -1.0e-3;           ///< the tray's centre (slots are drawn within its half-size)
  double tray_y_m = 0.0;
  double plate_x_m = 1.5e-3;  ///< the plate's centre (bores likewise)
  double plate_y_m = 0.0;
  double half_size_m = 0.75e-3;  ///< half the side of the tray's and the plate's areas
  /// The microworld every part is put in (adhesion, friction, gripper, force limits); its part,
  /// hole, start and target are the job's.
  microworld::PickPlaceParams world;

  template <class V>
  void visit(V& v) {
    v("parts", parts);
    v("seed", seed);
    v("min_side_m", min_side_m);
    v("max_side_m", max_side_m);
    v("part_height_m", part_height_m);
    v("min_clearance_m", min_clearance_m);
    v("max_clearance_m", max_clearance_m);
    v("hole_depth_m", hole_depth_m);
    v("slot_error_m", slot_error_m);
    v("max_yaw_rad", max_yaw_rad);
    v("slot_yaw_error_rad", slot_yaw_error_rad);
    v("tray_x_m", tray_x_m);
    v("tray_y_m", tray_y_m);
    v("plate_x_m", plate_x_m);
    v("plate_y_m", plate_y_m);
    v("half_size_m", half_size_m);
    v("world", world);
  }
  /// Throws mc::InvalidParams naming the key: counts and ranges, a pin the open gripper cannot
  /// pass around, a pin too short to be held above a full bore, a slot error that would put a
  /// pin outside the fingers' flats, areas beyond the stage's reach.
  void validate() const;
};

/// One part of the batch.
struct AssemblyJob {
  int index = 0;
  microworld::PickPlaceParams world;     ///< the true scene: the pin where it really is
  Eigen::Vector2d nominal_part_m{0, 0};  ///< its slot's nominal position (what the cell is told)
  Eigen::Vector2d target_m{0, 0};        ///< its bore's position (told, and true)
  double nominal_part_yaw_rad = 0.0;     ///< its slot's orientation (told)
  double target_yaw_rad = 0.0;           ///< its bore's (told, and true)
  double side_m = 0.0, clearance_m = 0.0;
};

/// The batch's jobs, the same for the same parameters (validated here).
std::vector<AssemblyJob> assembly_jobs(const AssemblyBatchParams& params);

}  // namespace mc::cell
