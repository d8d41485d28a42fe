#include "microcobot/tweezers/piezo_brake.h"

#include "microcobot/core/error.h"

namespace mc::tweezers {

double piezo_push_force(double max_force_N, double travel_used) {
  require_non_negative(max_force_N, "max_force_N");
  require_in_range(travel_used, 0.0, 1.0, "travel_used");
  return max_force_N * (1.0 - travel_used);
}

double piezo_block_force(double max_force_N, double travel_used, double mu, double geometry) {
  require_non_negative(mu, "mu");
  require_non_negative(geometry, "geometry");
  return piezo_push_force(max_force_N, travel_used) * mu * geometry;
}

}  // namespace mc::tweezers
