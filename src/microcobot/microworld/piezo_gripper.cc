#include "microcobot/microworld/piezo_gripper.h"

#include <algorithm>
#include <cmath>

namespace mc::microworld {

void PiezoGripperParams::validate() const {
  require_non_negative(min_opening_m, "gripper.min_opening_m");
  require(max_opening_m > min_opening_m, "gripper.max_opening_m", "must be > min_opening_m", max_opening_m);
  require_positive(time_constant_s, "gripper.time_constant_s");
  require_positive(max_speed_m_s, "gripper.max_speed_m_s");
  require_positive(finger_stiffness_N_m, "gripper.finger_stiffness_N_m");
  require_positive(finger_length_m, "gripper.finger_length_m");
  require(std::isfinite(finger_width_m) && finger_width_m >= 5e-6 && finger_width_m <= 1e-3,
          "gripper.finger_width_m", "must be within [5 um, 1 mm]", finger_width_m);
  require(std::isfinite(finger_thickness_m) && finger_thickness_m >= 5e-6 && finger_thickness_m <= 1e-3,
          "gripper.finger_thickness_m", "must be within [5 um, 1 mm]", finger_thickness_m);
  require(std::isfinite(shake_amplitude_m) && shake_amplitude_m >= 0.0 && shake_amplitude_m <= 20e-6,
          "gripper.shake_amplitude_m", "must be within [0, 20 um]", shake_amplitude_m);
  require(std::isfinite(shake_frequency_Hz) && shake_frequency_Hz > 0.0 && shake_frequency_Hz <= 100e3,
          "gripper.shake_frequency_Hz", "must be within (0, 100 kHz]", shake_frequency_Hz);
  require(std::isfinite(tip_misalignment_m) && std::abs(tip_misalignment_m) <= 200e-6,
          "gripper.tip_misalignment_m", "must be within [-200 um, 200 um]", tip_misalignment_m);
  require(std::isfinite(tip_face_height_m) && tip_face_height_m >= 1e-6 && tip_face_height_m <= 1e-3,
          "gripper.tip_face_height_m", "must be within [1 um, 1 mm]", tip_face_height_m);
  align.validate("gripper.align");
}

void step_gripper(const PiezoGripperParams& p, PiezoGripperState& s, double command_m, double dt_s) noexcept {
  const double target = std::clamp(command_m, p.min_opening_m, p.max_opening_m);
  // Exact first-order response over dt, then the slew limit.
  const double alpha = 1.0 - std::exp(-dt_s / p.time_constant_s);
  double delta = alpha * (target - s.free_opening_m);
  const double max_delta = p.max_speed_m_s * dt_s;
  delta = std::clamp(delta, -max_delta, max_delta);
  s.free_opening_m = std::clamp(s.free_opening_m + delta, p.min_opening_m, p.max_opening_m);
}

double grip_force_N(const PiezoGripperParams& p, const PiezoGripperState& s, double width_m) noexcept {
  return s.free_opening_m < width_m ? 0.5 * p.finger_stiffness_N_m * (width_m - s.free_opening_m) : 0.0;
}

}  // namespace mc::microworld
