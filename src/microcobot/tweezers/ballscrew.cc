#include "microcobot/tweezers/ballscrew.h"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "microcobot/core/error.h"

namespace mc::tweezers {

double lead_angle(double diameter_m, double lead_m) {
  require_positive(diameter_m, "diameter_m");
  require_positive(lead_m, "lead_m");
  const double theta = std::atan(lead_m / (std::numbers::pi * diameter_m));
  // A lead beyond ~1e16 diameters makes the angle round to 90 deg, which no screw has (and which
  // the efficiencies refuse): blamed on the lead the caller gave, not on the derived angle.
  require(theta < std::numbers::pi / 2, "lead_m",
          fmt::format("too large for diameter_m = {:g} (the lead angle rounds to 90 deg)", diameter_m),
          lead_m);
  return theta;
}

double forward_efficiency(double lead_angle_rad, double mu) {
  require(lead_angle_rad > 0 && lead_angle_rad < std::numbers::pi / 2, "lead_angle_rad",
          "must be in (0, pi/2)", lead_angle_rad);
  require_non_negative(mu, "mu");
  const double phi = std::atan(mu);
  // theta + phi >= pi/2: the screw cannot be driven forward at all.
  if (lead_angle_rad + phi >= std::numbers::pi / 2) return 0.0;
  return std::tan(lead_angle_rad) / std::tan(lead_angle_rad + phi);
}

double backward_efficiency(double lead_angle_rad, double mu) {
  require(lead_angle_rad > 0 && lead_angle_rad < std::numbers::pi / 2, "lead_angle_rad",
          "must be in (0, pi/2)", lead_angle_rad);
  require_non_negative(mu, "mu");
  const double phi = std::atan(mu);
  if (lead_angle_rad <= phi) return 0.0;  // self-locking
  return std::tan(lead_angle_rad - phi) / std::tan(lead_angle_rad);
}

BallScrewEfficiency ball_screw_efficiency(double diameter_m, double lead_m, double mu) {
  BallScrewEfficiency out;
  out.lead_angle_rad = lead_angle(diameter_m, lead_m);
  out.forward_efficiency = forward_efficiency(out.lead_angle_rad, mu);
  out.backward_efficiency = backward_efficiency(out.lead_angle_rad, mu);
  return out;
}

double axial_force(double torque_Nm, double lead_m, double efficiency) {
  require_non_negative(torque_Nm, "torque_Nm");
  require_positive(lead_m, "lead_m");
  require_in_range(efficiency, 0.0, 1.0, "efficiency");
  return 2.0 * std::numbers::pi * efficiency * torque_Nm / lead_m;
}

}  // namespace mc::tweezers
