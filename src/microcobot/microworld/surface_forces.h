#pragma once
/// @file
/// Pull-off (adhesion) forces of the microworld, where surface forces dominate weight
/// (thesis §1.1.1, Table 1.1; [Israelachvili 2011]). Closed forms for the contacts of a
/// pick-and-place task:
///  - van der Waals, sphere on plane:  F = A R / (6 D^2)
///  - van der Waals, plane on plane:   F = A S / (6 pi D^3)   (S: true contact area)
///  - capillary meniscus, sphere on plane: F = 4 pi gamma R cos(theta)
/// A: Hamaker constant, D: contact separation (~0.4 nm), gamma: liquid surface tension,
/// theta: contact angle. Used to set each contact's pull-off force.

namespace mc::microworld {

/// Van der Waals pull-off of a sphere (radius R) on a plane (N).
double vdw_sphere_plane_N(double hamaker_J, double radius_m, double separation_m);
/// Van der Waals pull-off of two flat surfaces in contact over `area_m2` (N).
double vdw_plane_plane_N(double hamaker_J, double area_m2, double separation_m);
/// Capillary pull-off of a sphere (radius R) on a plane wetted by a liquid (N).
double capillary_sphere_plane_N(double surface_tension_N_m, double radius_m, double contact_angle_rad);

}  // namespace mc::microworld
