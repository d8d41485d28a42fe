#pragma once
/// @file
/// The roller / arc-track transmission between the ball-screw slider and the levers (thesis
/// section 4.4.2, eq. 4.5, Fig. 4.20-4.21).

namespace mc::tweezers {

/// Force at each finger for the ball screw's axial force (eq. 4.5): the slider pushes both
/// levers, so each receives F_X = F_a / 2, and F_Y = eta_t F_X / tan(alpha), alpha being the
/// angle between the contact tangent and the axis (constant by design, 63 deg in the thesis).
double finger_force(double axial_force_N, double alpha_rad, double eta_t);

/// Magnetic preload that keeps the roller on its track while the motor closes the tweezers
/// (section 4.4.2): the attraction acts along the contact normal, which makes the angle alpha
/// with the opening direction, so pulling a finger force F_Y needs N > F_Y / cos(alpha).
/// The thesis's 1.75 N closing force and alpha = 63 deg give 3.85 N ("> 3.9 N").
double min_preload(double closing_force_N, double alpha_rad);

/// Axial force the actuator must provide for a force F_Y at each finger (inverse of eq. 4.5).
double required_axial_force(double finger_force_N, double alpha_rad, double eta_t);

}  // namespace mc::tweezers
