#pragma once
/// @file
/// The technical specifications of the TéléTweez (thesis Table 4.3) and the minimum actuator
/// force they imply (eq. 4.1).

namespace mc::tweezers {

/// Force needed to hold a tweezers of clamping stiffness k closed over an opening d (eq. 4.1):
/// F_act = k d. The thesis's 250 N/m and 7 mm give 1.75 N.
double stiffness_force(double stiffness_N_per_m, double opening_m);

/// Table 4.3. Defaults are the thesis's values.
struct TweezersSpecs {
  double max_voltage_V = 100.0;                         ///< section 4.3.2.1 (safety, energy)
  double max_current_A = 2.0;                           ///< section 4.3.2.1
  double clamping_stiffness_N_per_m = 250.0;            ///< Table 4.2 / 4.3, at the fingers
  double static_opening_tip_m = 7e-3;                   ///< Table 4.3
  double min_mass_kg = 5e-3, max_mass_kg = 70e-3;       ///< Table 4.3
  double min_length_m = 115e-3, max_length_m = 160e-3;  ///< Table 4.3
  /// Eq. 4.1: the force the actuator system must produce at the fingers.
  double min_force_N() const { return stiffness_force(clamping_stiffness_N_per_m, static_opening_tip_m); }
};

}  // namespace mc::tweezers
