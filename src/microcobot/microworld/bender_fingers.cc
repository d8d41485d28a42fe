#include "microcobot/microworld/bender_fingers.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mc::microworld {

void BenderFingersParams::validate() const {
  grasp.validate("gripper.grasp");
  align.validate("gripper.align");
  require(std::isfinite(rest_half_opening_m) && rest_half_opening_m > 0.0 && rest_half_opening_m <= 1e-3,
          "gripper.rest_half_opening_m", "must be within (0, 1 mm]", rest_half_opening_m);
  require_positive(contact_stiffness_N_m, "gripper.contact_stiffness_N_m");
  require(std::isfinite(tip_face_height_m) && tip_face_height_m >= 1e-6 && tip_face_height_m <= 1e-3,
          "gripper.tip_face_height_m", "must be within [1 um, 1 mm]", tip_face_height_m);
  require(std::isfinite(friction_coefficient) && friction_coefficient > 0.0 && friction_coefficient <= 2.0,
          "gripper.friction_coefficient", "must be within (0, 2]", friction_coefficient);
  require(std::isfinite(gain_mismatch) && std::abs(gain_mismatch) <= 0.5, "gripper.gain_mismatch",
          "must be within [-0.5, 0.5]", gain_mismatch);
}

PiezoBenderParams finger_bender(const BenderFingersParams& p, const PiezoBenderParams& base, int k) noexcept {
  PiezoBenderParams b = base;
  if (k == 1) {
    b.gain_m_V *= 1.0 + p.gain_mismatch;
    b.bw_A_m_V *= 1.0 + p.gain_mismatch;
  }
  return b;
}

void step_fingers(const BenderFingersParams& p, BenderFingersState& s, const BenderDrives& d,
                  double dt_s) noexcept {
  for (int k = 0; k < 2; ++k) {
    const auto i = static_cast<std::size_t>(k);
    step_bender(finger_bender(p, p.grasp, k), s.grasp[i], d.grasp_V[i], dt_s);
    step_bender(finger_bender(p, p.align, k), s.align[i], d.align_V[i], dt_s);
  }
}

TipReading read_tips(const BenderFingersParams& p, const BenderFingersState& s,
                     double substrate_z_m) noexcept {
  TipReading r;
  for (std::size_t k = 0; k < 2; ++k) {
    const double side = k == 0 ? -1.0 : 1.0;
    // A positive grasp deflection opens: each tip moves outward.
    r.x_m[k] = side * (p.rest_half_opening_m + s.grasp[k].y_m);
    const double free_z = s.mount_z_m[k] + s.align[k].y_m;
    if (free_z < substrate_z_m) {
      r.z_m[k] = substrate_z_m;
      r.contact_N[k] = p.contact_stiffness_N_m * (substrate_z_m - free_z);
    } else {
      r.z_m[k] = free_z;
    }
  }
  return r;
}

double misalignment_m(const BenderFingersParams& p, const BenderFingersState& s) noexcept {
  const TipReading r = read_tips(p, s, -std::numeric_limits<double>::infinity());
  return r.z_m[1] - r.z_m[0];
}

double holding_force_N(const BenderFingersParams& p, double grip_force_N, double misalignment) noexcept {
  const double overlap = std::max(0.0, 1.0 - std::abs(misalignment) / p.tip_face_height_m);
  return 2.0 * p.friction_coefficient * std::max(0.0, grip_force_N) * overlap;
}

double part_tilt_rad(double misalignment, double width_m) noexcept {
  return width_m > 0.0 ? std::atan2(misalignment, width_m) : 0.0;
}

}  // namespace mc::microworld
