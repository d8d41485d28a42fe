#include "microcobot/tweezers/specs.h"

#include "microcobot/core/error.h"

namespace mc::tweezers {

double stiffness_force(double stiffness_N_per_m, double opening_m) {
  require_non_negative(stiffness_N_per_m, "stiffness_N_per_m");
  require_non_negative(opening_m, "opening_m");
  return stiffness_N_per_m * opening_m;
}

}  // namespace mc::tweezers
