#pragma once
/// @file
/// Static analysis of a ball screw (thesis appendix B, eq. B.1-B.9, and eq. 4.4).
///
/// The thread, unrolled over one turn, is an incline of height `lead` over a base of
/// pi*diameter: its lead angle theta satisfies tan(theta) = lead / (pi d). Friction is a cone of
/// half-angle phi = atan(mu). Forward transmission (torque drives translation, haptic display)
/// has efficiency tan(theta)/tan(theta+phi) (eq. B.6); backward transmission (translation
/// back-drives rotation, the operator moving the motor) has tan(theta-phi)/tan(theta)
/// (eq. B.9 with the sign corrected, docs/errata.md, "Eq. B.9"). The screw is reversible only while
/// theta > phi.

namespace mc::tweezers {

/// Lead angle theta [rad] of a screw of nominal diameter `diameter_m` and lead `lead_m` per turn:
/// tan(theta) = lead / (pi d) (app. B, Fig. B.1). Throws InvalidParams for non-positive input.
double lead_angle(double diameter_m, double lead_m);

/// Forward efficiency eta_f = tan(theta) / tan(theta + atan(mu)) (eq. B.6), mu >= 0.
double forward_efficiency(double lead_angle_rad, double mu);

/// Backward efficiency eta_b = tan(theta - atan(mu)) / tan(theta) (eq. B.9, erratum 5 in docs/errata.md).
/// Returns 0 when the screw is self-locking (theta <= atan(mu)): nothing is transmitted back.
double backward_efficiency(double lead_angle_rad, double mu);

/// The three figures of a ball screw, as `microcobot design ballscrew` prints them.
struct BallScrewEfficiency {
  double lead_angle_rad = 0;
  double forward_efficiency = 0;
  double backward_efficiency = 0;
};

/// Evaluates eq. B.6 and B.9 for a screw (diameter, lead, friction coefficient).
BallScrewEfficiency ball_screw_efficiency(double diameter_m, double lead_m, double mu);

/// Axial force of the ball screw driven by a torque (eq. 4.4, from eq. B.1-B.2):
/// F_a = 2 pi eta_f C / p. The thesis's 2.2 mN m, 1 mm lead and eta_f = 0.89 give 12.3 N.
double axial_force(double torque_Nm, double lead_m, double forward_efficiency);

}  // namespace mc::tweezers
