#include "microcobot/teleop/model_mediated_master.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::teleop {

void ModelMediatedMasterParams::validate() const {
  require_in_range(time_constant_s, 0.0, 10.0, "mmt.time_constant_s");
  require_positive(servo_stiffness_N_m, "servo_stiffness_N_m");
  require_positive(max_force_N, "max_force_N");
}

ModelMediatedMaster::ModelMediatedMaster(const ModelMediatedMasterParams& p, const ContactModel& prior)
    : p_(p), model_(prior), target_(prior) {
  p_.validate();
  require(std::isfinite(prior.wall_m), "mmt prior wall_m", "must be finite", prior.wall_m);
  require_positive(prior.stiffness_N_m, "mmt.prior_stiffness_N_m");
}

double ModelMediatedMaster::rendered_stiffness_N_m() const {
  return model_.stiffness_N_m * p_.servo_stiffness_N_m / (model_.stiffness_N_m + p_.servo_stiffness_N_m);
}

double ModelMediatedMaster::force(double x, double v, double dt_s) noexcept {
  const double a = dt_s / (p_.time_constant_s + dt_s);  // eq. (1)
  model_.wall_m += a * (target_.wall_m - model_.wall_m);
  model_.stiffness_N_m += a * (target_.stiffness_N_m - model_.stiffness_N_m);
  model_.sent_s = target_.sent_s;
  const double model_f =
      std::clamp(rendered_stiffness_N_m() * std::max(0.0, x - model_.wall_m), 0.0, p_.max_force_N);  // (2)
  double f = model_f;
  // Eq. (3): PO after this step if f were rendered; an input step never lowers it.
  const double po = e_.in_J - e_.out_J + std::min(0.0, f * v) * dt_s;
  if (p_.passivity && po < 0.0 && v != 0.0) f += (-po / (v * v * dt_s)) * v;  // alpha v, alpha = -PO/(v^2 dt)
  // The actuator saturates: the books take the force the handle actually got, so that a
  // saturated damper would show as PO < 0 instead of hiding.
  f = std::clamp(f, -p_.max_force_N, p_.max_force_N);
  dissipated_J_ += (f - model_f) * v * dt_s;
  e_.add(f * v, dt_s);
  return f;
}

}  // namespace mc::teleop
