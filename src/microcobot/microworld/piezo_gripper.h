#pragma once
/// @file
/// The slave micro-gripper (Percipio's PiezoGripper, thesis §1.1.4, Fig. 1.14): two
/// piezoelectric bender fingers closing along x. Each finger is a first-order system
/// (bender bandwidth) with a slew limit, and a spring of stiffness k_finger at its tip, so
/// that a part of width w held between fingers commanded to an opening o < w is squeezed by
///     F_grip = k_finger (w - o) / 2      (each finger deflects by (w - o) / 2).
///
/// Each finger also has its vertical (align) bender (thesis §1.1.4: "the vertical motion is used to
/// align the fingertips", bender_fingers.h): the pick-and-place world carries their state, and a
/// finger mounted higher than the other (tip_misalignment_m) grips with the faces' overlap only.

#include "microcobot/core/params.h"
#include "microcobot/microworld/piezo_bender.h"

namespace mc::microworld {

struct PiezoGripperParams {
  double max_opening_m = 600e-6;       ///< fully open (a 300 um part fits with margin)
  double min_opening_m = 0.0;          ///< fully closed (fingers touch)
  double time_constant_s = 2e-3;       ///< bender response (first order)
  double max_speed_m_s = 5e-3;         ///< slew limit of the opening
  double finger_stiffness_N_m = 50.0;  ///< bender tip stiffness
  double finger_length_m = 2e-3;       ///< tips reach this far below the gripper reference
  /// The fingers' width across their closing direction, as the microscope sees them (drawn by the
  /// camera's scene, looked for by the vision positioner and the grip gauge).
  double finger_width_m = 40e-6;
  /// The fingers' thickness along their closing axis, outward from their inner faces (where they
  /// strike a neighbouring part, microworld/neighbours.h).
  double finger_thickness_m = 50e-6;
  /// The drive's release burst (release.h, "shake"): the opened fingers vibrate along their
  /// closing axis at this amplitude and frequency at the tips. 1 um at 5 kHz, below the first
  /// bending mode of a 2 mm piezo bender (tens of kHz), accelerates the tips at 990 m/s^2.
  double shake_amplitude_m = 1e-6;
  double shake_frequency_Hz = 5e3;
  /// The fingers' vertical mounting error: finger 1's tip this much above finger 0's at 0 V on
  /// the align drives (each tip half of it from the gripper's reference height, finger 0 below).
  /// 0: level tips, the grip of the closing model alone.
  double tip_misalignment_m = 0.0;
  /// The height of a tip's gripping face: a misalignment dz holds over 1 - |dz| / this of it
  /// (bender_fingers.h, holding_force_N).
  double tip_face_height_m = 50e-6;
  PiezoBenderParams align;  ///< each finger's vertical bender (positive drive raises its tip)

  template <class V>
  void visit(V& v) {
    v("max_opening_m", max_opening_m);
    v("min_opening_m", min_opening_m);
    v("time_constant_s", time_constant_s);
    v("max_speed_m_s", max_speed_m_s);
    v("finger_stiffness_N_m", finger_stiffness_N_m);
    v("finger_length_m", finger_length_m);
    v("finger_width_m", finger_width_m);
    v("finger_thickness_m", finger_thickness_m);
    v("shake_amplitude_m", shake_amplitude_m);
    v("shake_frequency_Hz", shake_frequency_Hz);
    v("tip_misalignment_m", tip_misalignment_m);
    v("tip_face_height_m", tip_face_height_m);
    v("align", align);
  }
  void validate() const;
};

struct PiezoGripperState {
  double free_opening_m = 600e-6;  ///< opening the fingers would have without a part between them
  bool shaking = false;            ///< the release burst is on (shake_amplitude_m, shake_frequency_Hz)
};

/// Advances the free opening toward `command_m` (clamped to the range) over `dt_s`.
/// Real-time safe.
void step_gripper(const PiezoGripperParams& p, PiezoGripperState& s, double command_m, double dt_s) noexcept;

/// Grip force on a part of width `width_m` between the fingers (0 if the fingers are open wider).
double grip_force_N(const PiezoGripperParams& p, const PiezoGripperState& s, double width_m) noexcept;

}  // namespace mc::microworld
