#include "microcobot/teleop/passivity.h"

#include <cmath>

namespace mc::teleop {

double MasterPassivityController::force(double f, double v, double remote_in_J, double dt_s) noexcept {
  double power = f * v;  // into the channel
  const double po = remote_in_J - (e_.out_J + (power < 0.0 ? -power * dt_s : 0.0));
  if (enabled_ && po < 0.0 && v != 0.0) {
    // A damper alpha v dissipates exactly the excess -po over this sample.
    const double alpha = -po / (v * v * dt_s);
    f += alpha * v;
    power = f * v;
    dissipated_J_ -= po;
  }
  e_.add(power, dt_s);
  observed_J_ = remote_in_J - e_.out_J;
  return f;
}

double SlavePassivityController::velocity(double v, double f, double remote_in_J, double dt_s) noexcept {
  double out_power = f * v;  // out of the channel into the environment
  const double po = remote_in_J - (e_.out_J + (out_power > 0.0 ? out_power * dt_s : 0.0));
  if (enabled_ && po < 0.0 && f != 0.0) {
    // The commanded velocity reduced so that the energy delivered is what has arrived.
    v -= -po / (f * dt_s);
    out_power = f * v;
    dissipated_J_ -= po;
  }
  e_.add(-out_power, dt_s);
  observed_J_ = remote_in_J - e_.out_J;
  return v;
}

}  // namespace mc::teleop
