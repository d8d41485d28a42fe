#include "microcobot/microworld/surface_forces.h"

#include <cmath>

namespace mc::microworld {

double vdw_sphere_plane_N(double hamaker_J, double radius_m, double separation_m) {
  return hamaker_J * radius_m / (6.0 * separation_m * separation_m);
}

double vdw_plane_plane_N(double hamaker_J, double area_m2, double separation_m) {
  return hamaker_J * area_m2 / (6.0 * M_PI * separation_m * separation_m * separation_m);
}

double capillary_sphere_plane_N(double surface_tension_N_m, double radius_m, double contact_angle_rad) {
  return 4.0 * M_PI * surface_tension_N_m * radius_m * std::cos(contact_angle_rad);
}

}  // namespace mc::microworld
