#include "microcobot/teleop/safety_limits.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::teleop {

void SafetyLimitParams::validate() const {
  require(std::isfinite(grip_force_limit_N) && grip_force_limit_N > 0.0, "grip_force_limit_N",
          "must be a finite force > 0", grip_force_limit_N);
  require(std::isfinite(contact_force_limit_N) && contact_force_limit_N > 0.0, "contact_force_limit_N",
          "must be a finite force > 0", contact_force_limit_N);
  require(std::isfinite(finger_stiffness_N_m) && finger_stiffness_N_m > 0.0, "finger_stiffness_N_m",
          "must be a finite stiffness > 0", finger_stiffness_N_m);
  require(!std::isnan(floor_m) && floor_m < std::numeric_limits<double>::infinity(), "floor_m",
          "must be a number below +inf", floor_m);
}

SafetyLimits::SafetyLimits(const SafetyLimitParams& params) : p_(params) { p_.validate(); }

double SafetyLimits::limit_opening_m(double requested_m, double measured_opening_m, double grip_force_N,
                                     double last_command_m) const noexcept {
  double command = requested_m;
  if (std::isfinite(grip_force_N) && grip_force_N > 0.0 && std::isfinite(measured_opening_m)) {
    // In contact: the measured opening is the part's width w; F = k (w - o) / 2 stops at the
    // limit when o >= w - 2 F_max / k.
    command = std::max(command, measured_opening_m - 2.0 * p_.grip_force_limit_N / p_.finger_stiffness_N_m);
    if (grip_force_N > p_.grip_force_limit_N && std::isfinite(last_command_m))
      command = std::max(
          command, last_command_m + 2.0 * (grip_force_N - p_.grip_force_limit_N) / p_.finger_stiffness_N_m);
  }
  return command;
}

bool SafetyLimits::contact_over_limit(const Eigen::Vector3d& f) const noexcept {
  return f.allFinite() && f.norm() > p_.contact_force_limit_N;
}

void SafetyLimits::limit_target(Eigen::Vector3d& target, Eigen::Vector3d& velocity,
                                const Eigen::Vector3d& measured, const Eigen::Vector3d& f) const noexcept {
  if (contact_over_limit(f) && measured.allFinite()) {
    // The force pushes the tool out of the contact: keep the target no further along -f than
    // where the tool is now, and no feedforward into it.
    const Eigen::Vector3d out = f.normalized();
    const double ahead = (target - measured).dot(out);
    if (ahead < 0.0) target -= ahead * out;
    const double v_in = velocity.dot(out);
    if (v_in < 0.0) velocity -= v_in * out;
  }
  if (target.z() < p_.floor_m) {
    target.z() = p_.floor_m;
    velocity.z() = std::max(0.0, velocity.z());
  }
}

}  // namespace mc::teleop
