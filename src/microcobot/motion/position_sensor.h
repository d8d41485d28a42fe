#pragma once
/// @file
/// The position sensor of one axis of the XYZ stage (thesis §2.3: 0.1 nm resolution): the true
/// slider position plus white Gaussian noise, quantised to the resolution.

#include <cstdint>

#include "microcobot/core/rng.h"

namespace mc::motion {

struct PositionSensorParams {
  double resolution_m = 0.1e-9;  ///< quantisation step (thesis §2.3: 0.1 nm)
  double noise_rms_m = 1.0e-9;   ///< white noise standard deviation (1 nm RMS)
  int seed = 1;                  ///< noise stream (deterministic runs)

  template <class V>
  void visit(V& v) {
    v("resolution_m", resolution_m);
    v("noise_rms_m", noise_rms_m);
    v("seed", seed);
  }
  void validate() const;
};

/// A real-time sensor model: measure() never allocates.
class PositionSensor {
 public:
  explicit PositionSensor(const PositionSensorParams& p = {});
  /// round((x + n) / q) q with n ~ N(0, noise_rms^2).
  double measure(double true_position_m) noexcept;
  const PositionSensorParams& params() const { return p_; }

 private:
  PositionSensorParams p_;
  Rng rng_;
};

}  // namespace mc::motion
