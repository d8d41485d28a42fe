#include "microcobot/teleop/contact_estimator.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::teleop {

void ContactEstimatorParams::validate() const {
  require_positive(contact_threshold_N, "mmt.contact_threshold_N");
  require(std::isfinite(forgetting) && forgetting > 0.9 && forgetting <= 1.0, "mmt.forgetting",
          "must be within (0.9, 1]", forgetting);
  require_positive(min_spread_m, "mmt.min_spread_m");
}

ContactEstimator::ContactEstimator(const ContactEstimatorParams& p, const ContactModel& prior)
    : p_(p), model_(prior) {
  p_.validate();
  require(std::isfinite(prior.wall_m), "mmt prior wall_m", "must be finite", prior.wall_m);
  require_positive(prior.stiffness_N_m, "mmt.prior_stiffness_N_m");
}

void ContactEstimator::update(double x_s, double f_e) noexcept {
  in_contact_ = f_e > p_.contact_threshold_N;
  if (!in_contact_) {
    // No force at x_s: the wall is not before it.
    model_.wall_m = std::max(model_.wall_m, x_s);
    return;
  }
  if (!have_origin_) {
    x0_ = x_s;
    have_origin_ = true;
  }
  const double x = x_s - x0_, l = p_.forgetting;
  w_ = l * w_ + 1.0;
  sx_ = l * sx_ + x;
  sf_ = l * sf_ + f_e;
  sxx_ = l * sxx_ + x * x;
  sxf_ = l * sxf_ + x * f_e;
  const double mx = sx_ / w_, mf = sf_ / w_;
  const double var = std::max(0.0, sxx_ / w_ - mx * mx), cov = sxf_ / w_ - mx * mf;
  // Eq. (2): the slope where the samples spread enough to show it, and only a positive one
  // (a wall pushes back); else the stiffness held.
  if (var > p_.min_spread_m * p_.min_spread_m && cov > 0.0) model_.stiffness_N_m = cov / var;
  model_.wall_m = x0_ + mx - mf / model_.stiffness_N_m;
}

}  // namespace mc::teleop
