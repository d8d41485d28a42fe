#pragma once
/// @file
/// A small batch of watchmaking-like insertions: N square pins taken from a
/// tray and inserted into the bores of an assembly plate. Each pin has its own side (100-300 um),
/// each bore its own radial clearance (3-20 um), drawn from a seeded generator; the pins sit in
/// their tray slots with a position error (the slot's play) that the cell does not know: the
/// robot is told each slot's nominal position and each bore's, as a fixtured tray and plate
/// would give them, and must cope with the rest (the closing fingers centre the pin along x; y is
/// found by a force-guarded search, assembly_task.h). Each slot and each bore has its own
/// orientation, uniform within +-max_yaw_rad (+-45 deg: any orientation of a
/// square), told to the cell; a pin sits in its slot turned by a further error it is not told (the
/// grasp's squeeze takes it out). The orientations come from their own stream of the seed: with
/// max_yaw_rad 0 and slot_yaw_error_rad 0 a batch is the one of before the rotary axis.
///
/// Flat parts: a share flat_fraction of the parts, drawn from a stream of
/// their own, are flat plates (flat_side_m x flat_side_m x flat_thickness_m, a bridge's blank) to
/// be placed on flat, dry seats within seat_tolerance_m, where adhesion, not gravity, decides the
/// release (microworld/release.h): the plate clings to each finger with flat_finger_pulloff_N, and
/// each seat's finish holds it with a pull-off drawn uniform in [flat_seat_min_pulloff_N,
/// flat_seat_max_pulloff_N] (told to the cell, as a plate's inspection sheet would). Each part's
/// release strategy is `release`; `auto` chooses per part the first of open, roll, shake whose
/// margin (release.h) reaches min_release_margin, else the one of largest margin.
///
/// Several parts in one scene: with `layout: grid` the tray's slots and the
/// plate's bores are grids of pitch grid_pitch_m (n x n within each area's half_size_m), filled in
/// order, n^2 parts a load; each part's microworld holds the rest of its load as neighbours
/// (microworld/neighbours.h): the parts after it still in their slots, the ones before it placed on
/// their bores (pins standing part_height_m - hole_depth_m proud, plates their thickness). The
/// orientations and slot errors are drawn as in the random layout. `layout: random` (the default)
/// is the batch of before: each part alone in its scene.
///
/// One job is one part: its microworld (microworld::PickPlaceParams: the pin, the bore, the
/// adhesion of the default 300 um scene; or the plate, its seat) and what the cell is told. The cycles of a
/// batch run one after another on a fresh platform each (cell_run.h), so neighbouring parts do not interact
/// yet. Positions are world coordinates (the substrate's top at z = 0); SI units.

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "microcobot/microworld/pick_place_world.h"
#include "microcobot/microworld/release.h"

namespace mc::cell {

struct AssemblyBatchParams {
  int parts = 10;                      ///< pins in the batch, [1, 10000]
  int seed = 1;                        ///< the generator's seed: the same seed gives the same batch
  double min_side_m = 100e-6;          ///< pin side, uniform in [min, max] (100-300 um)
  double max_side_m = 300e-6;          ///< the largest pin side (min_side_m is the smallest)
  double part_height_m = 600e-6;       ///< every pin's height
  double min_clearance_m = 3e-6;       ///< radial clearance of the bores, uniform in [min, max]
  double max_clearance_m = 20e-6;      ///< (3-20 um)
  double hole_depth_m = 300e-6;        ///< the bores' depth
  double slot_error_m = 5e-6;          ///< standard deviation of a pin in its slot (x and y)
  double max_yaw_rad = M_PI / 4;       ///< slots' and bores' orientations, uniform in [-max, max]
  double slot_yaw_error_rad = 0.0175;  ///< standard deviation of a pin's yaw in its slot (1 deg)
  double tray_x_m = -1.0e-3;           ///< the tray's centre (slots are drawn within its half-size)
  double tray_y_m = 0.0;               ///< the tray centre's y
  double plate_x_m = 1.5e-3;           ///< the plate's centre (bores likewise)
  double plate_y_m = 0.0;              ///< the plate centre's y
  double half_size_m = 0.75e-3;        ///< half the side of the tray's and the plate's areas
  std::string layout = "random";       ///< random (each part alone) or grid (header)
  double grid_pitch_m = 700e-6;        ///< the grids' pitch (layout grid)
  double flat_fraction = 0.0;          ///< the share of flat parts, [0, 1] (header)
  double flat_side_m = 300e-6;         ///< a flat part's side (300 um)
  double flat_thickness_m = 50e-6;     ///< a flat part's thickness (50 um)
  double seat_tolerance_m = 10e-6;     ///< a flat part rests within this of its seat's centre
  /// A flat part's pull-off per finger: van der Waals over its edge face (microworld::flat_part_scene).
  double flat_finger_pulloff_N = microworld::flat_part_scene().finger_pulloff_N;
  double flat_seat_min_pulloff_N = 5e-6;  ///< the seats' pull-off, uniform in [min, max]
  double flat_seat_max_pulloff_N = 60e-6;
  /// The standard deviation (x and y) of each bore's (or seat's) true position from its drawing:
  /// the plate's fixture and machining. The cell is told the drawing; its camera sees the bore
  /// (cell_camera.h, look_bore). 0: the bores are where the drawing says.
  double bore_error_m = 0.0;
  /// The largest tilt of each part's seat on what carries it (world.seat_tilt_x_rad, _y_rad): a
  /// magnitude uniform in [0, max] about a horizontal axis of uniform direction, from a stream of
  /// its own; not told to the cell, which levels the seat on the parallel positioner
  /// (seat_levelling.h). 0: each part's seat is world's.
  double max_seat_tilt_rad = 0.0;
  /// The largest vertical misalignment of the gripper's tips in each part's cycle
  /// (world.gripper.tip_misalignment_m, uniform in [-max, max], from a stream of its own): a finger
  /// remounted off level, which the cell's first step levels (tip_levelling_step.h). 0: the world's.
  double max_tip_misalignment_m = 0.0;
  std::string release = "auto";     ///< auto, open, shake or roll (header)
  double min_release_margin = 1.2;  ///< auto: the margin a strategy must reach to be chosen
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
    v("layout", layout);
    v("grid_pitch_m", grid_pitch_m);
    v("flat_fraction", flat_fraction);
    v("flat_side_m", flat_side_m);
    v("flat_thickness_m", flat_thickness_m);
    v("seat_tolerance_m", seat_tolerance_m);
    v("flat_finger_pulloff_N", flat_finger_pulloff_N);
    v("flat_seat_min_pulloff_N", flat_seat_min_pulloff_N);
    v("flat_seat_max_pulloff_N", flat_seat_max_pulloff_N);
    v("bore_error_m", bore_error_m);
    v("max_seat_tilt_rad", max_seat_tilt_rad);
    v("max_tip_misalignment_m", max_tip_misalignment_m);
    v("release", release);
    v("min_release_margin", min_release_margin);
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
  Eigen::Vector2d target_m{0, 0};     ///< its bore's position as drawn (told; world.target_m is the true one)
  double nominal_part_yaw_rad = 0.0;  ///< its slot's orientation (told)
  double target_yaw_rad = 0.0;        ///< its bore's (told, and true)
  double side_m = 0.0, clearance_m = 0.0;  ///< a flat part's clearance: its seat's tolerance
  bool flat = false;                       ///< a flat part on a flat seat
  microworld::ReleaseStrategy release = microworld::ReleaseStrategy::kOpen;
  double release_margin = 0.0;  ///< the chosen strategy's (release.h)
};

/// The release strategy `release` ("auto" or a strategy's name) gives a part in `world` (in a bore
/// or not), and its margin.
microworld::ReleaseStrategy choose_release(const microworld::PickPlaceParams& world, bool in_bore,
                                           const std::string& release, double min_margin, double& margin);

/// The slots (or bores) of a grid layout within an area of half side `half_size_m` (n x n, row by row).
int grid_cells_per_side(double half_size_m, double pitch_m) noexcept;

/// The batch's jobs, the same for the same parameters (validated here).
std::vector<AssemblyJob> assembly_jobs(const AssemblyBatchParams& params);

}  // namespace mc::cell
