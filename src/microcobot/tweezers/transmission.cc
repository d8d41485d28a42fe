#include "microcobot/tweezers/transmission.h"

#include <cmath>
#include <numbers>

#include "microcobot/core/error.h"

namespace mc::tweezers {

namespace {
void check_alpha(double alpha_rad) {
  require(alpha_rad > 0 && alpha_rad < std::numbers::pi / 2, "alpha_rad", "must be in (0, pi/2)", alpha_rad);
}
}  // namespace

double finger_force(double axial_force_N, double alpha_rad, double eta_t) {
  require_non_negative(axial_force_N, "axial_force_N");
  check_alpha(alpha_rad);
  require(eta_t > 0 && eta_t <= 1, "eta_t", "must be in (0, 1]", eta_t);
  return eta_t * (0.5 * axial_force_N) / std::tan(alpha_rad);
}

double min_preload(double closing_force_N, double alpha_rad) {
  require_non_negative(closing_force_N, "closing_force_N");
  check_alpha(alpha_rad);
  return closing_force_N / std::cos(alpha_rad);
}

double required_axial_force(double finger_force_N, double alpha_rad, double eta_t) {
  require_non_negative(finger_force_N, "finger_force_N");
  check_alpha(alpha_rad);
  require(eta_t > 0 && eta_t <= 1, "eta_t", "must be in (0, 1]", eta_t);
  return 2.0 * finger_force_N * std::tan(alpha_rad) / eta_t;
}

}  // namespace mc::tweezers
