#pragma once
/// @file
/// The 4-DOF PiezoGripper (thesis §1.1.4, Fig. 1.14): two fingers, each a pair of piezo benders
/// (piezo_bender.h), one deflecting its tip along the closing axis x (grasp), one along z
/// (align). "Horizontal motion of both fingers is used to the grasping/release of micro-objects,
/// the vertical motion is used to align the fingertips" (thesis §1.1.4). Here: the four benders
/// stepped together, the tips' positions in the gripper's frame, their contact with a substrate
/// below, and what a vertical misalignment does to a grip.
///
/// Frame: x along the closing axis (finger 0 on -x, finger 1 on +x), z up; a tip's position is
/// its rest position (x = -+rest_half_opening_m, z = 0) plus its benders' deflections. A tip
/// below the substrate (z_tip < substrate_z) is held on it: its z is the substrate's and it
/// presses with contact_stiffness_N_m times the depth its bender would have gone.
///
/// A grip with the tips at different heights: the two contact forces, offset vertically by the
/// misalignment dz, hold the part over the faces' overlap only, so the friction that holds the
/// part against a pull is
///     F_hold = 2 mu F_grip max(0, 1 - |dz| / tip_face_height_m)
/// and the part between them turns by atan(dz / width) (an assumption of this model: the faces
/// as rigid flats of height tip_face_height_m; docs/model.md, docs/errata.md).

#include <array>

#include "microcobot/microworld/piezo_bender.h"

namespace mc::microworld {

struct BenderFingersParams {
  PiezoBenderParams grasp;              ///< each finger's closing bender (x)
  PiezoBenderParams align;              ///< each finger's vertical bender (z)
  double rest_half_opening_m = 150e-6;  ///< each tip's distance from the axis at 0 V
  double contact_stiffness_N_m = 50.0;  ///< a tip pressed on the substrate (the bender's own)
  double tip_face_height_m = 50e-6;     ///< the height of a tip's gripping face
  double friction_coefficient = 0.5;    ///< tip on part
  /// The two fingers' manufacturing spread: finger 1's benders' gains are (1 + gain_mismatch)
  /// times finger 0's (the tips then misalign as the drives go).
  double gain_mismatch = 0.0;

  template <class V>
  void visit(V& v) {
    v("grasp", grasp);
    v("align", align);
    v("rest_half_opening_m", rest_half_opening_m);
    v("contact_stiffness_N_m", contact_stiffness_N_m);
    v("tip_face_height_m", tip_face_height_m);
    v("friction_coefficient", friction_coefficient);
    v("gain_mismatch", gain_mismatch);
  }
  /// Throws mc::InvalidParams naming the field.
  void validate() const;
};

/// The four drives, V: grasp 0, grasp 1 (positive opens), align 0, align 1 (positive raises).
struct BenderDrives {
  std::array<double, 2> grasp_V{};
  std::array<double, 2> align_V{};
};

struct BenderFingersState {
  std::array<PiezoBenderState, 2> grasp;
  std::array<PiezoBenderState, 2> align;
  /// Where each finger's tip would be at rest without the substrate, z, from its assembly: a
  /// finger mounted low or high (the misalignment the align benders take out).
  std::array<double, 2> mount_z_m{};
};

/// The tips seen by the world: positions in the gripper's frame and their vertical contact.
struct TipReading {
  std::array<double, 2> x_m{};
  std::array<double, 2> z_m{};        ///< held at substrate_z where in contact
  std::array<double, 2> contact_N{};  ///< each tip's vertical contact force (0 off the substrate)
};

/// Advances the four benders over `dt_s` toward `drives` (finger 1's gains scaled by
/// 1 + gain_mismatch). Real-time safe.
void step_fingers(const BenderFingersParams& p, BenderFingersState& s, const BenderDrives& drives,
                  double dt_s) noexcept;

/// The tips against a substrate at `substrate_z_m` in the gripper's frame (-inf: none).
TipReading read_tips(const BenderFingersParams& p, const BenderFingersState& s,
                     double substrate_z_m) noexcept;

/// The tips' vertical misalignment, z of finger 1 minus z of finger 0, free of any substrate.
double misalignment_m(const BenderFingersParams& p, const BenderFingersState& s) noexcept;

/// The friction that holds a part gripped with `grip_force_N` against a pull, given the tips'
/// misalignment (the header's F_hold), and the part's tilt between tips `width_m` apart.
double holding_force_N(const BenderFingersParams& p, double grip_force_N, double misalignment_m) noexcept;
double part_tilt_rad(double misalignment_m, double width_m) noexcept;

/// Finger k's parameters for a bender of `base` (finger 1's gains scaled by the mismatch).
PiezoBenderParams finger_bender(const BenderFingersParams& p, const PiezoBenderParams& base, int k) noexcept;

}  // namespace mc::microworld
