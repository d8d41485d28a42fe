#include "microcobot/motion/position_sensor.h"

#include <cmath>

#include "microcobot/core/error.h"

namespace mc::motion {

void PositionSensorParams::validate() const {
  require_positive(resolution_m, "sensor.resolution_m");
  require_non_negative(noise_rms_m, "sensor.noise_rms_m");
}

PositionSensor::PositionSensor(const PositionSensorParams& p)
    : p_(p), rng_(static_cast<std::uint64_t>(p.seed)) {
  p_.validate();
}

double PositionSensor::measure(double true_position_m) noexcept {
  const double noisy =
      p_.noise_rms_m > 0.0 ? true_position_m + p_.noise_rms_m * rng_.normal() : true_position_m;
  return p_.resolution_m * std::round(noisy / p_.resolution_m);
}

}  // namespace mc::motion
