#include "microcobot/microworld/optical_trap.h"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "microcobot/core/error.h"

namespace mc::microworld {

void OpticalTrapParams::validate() const {
  require_positive(bead_radius_m, "bead_radius_m");
  require_positive(viscosity_Pa_s, "viscosity_Pa_s");
  require_positive(temperature_K, "temperature_K");
  require_positive(trap_stiffness_N_per_m, "trap_stiffness_N_per_m");
  require_positive(obstacle_radius_m, "obstacle_radius_m");
  require_non_negative(contact_stiffness_N_per_m, "contact_stiffness_N_per_m");
  require(std::isfinite(escape_distance_m) && escape_distance_m >= 0.0 && escape_distance_m <= 1e-3,
          "escape_distance_m", "must be within [0, 1 mm] (0: the bead radius times e^(1/4))",
          escape_distance_m);
  // A physical lower bound on the step (the bead's inertia-free dynamics need nothing finer;
  // the work budget of a run is duration / dt_s).
  require(std::isfinite(dt_s) && dt_s >= 1e-9, "dt_s", "must be >= 1e-09 s", dt_s);
  // The contact force is explicit over a step: its relaxation must be resolved.
  const double gamma = 6.0 * std::numbers::pi * viscosity_Pa_s * bead_radius_m;
  require(contact_stiffness_N_per_m * dt_s / gamma < 0.5, "contact_stiffness_N_per_m",
          fmt::format("too stiff for dt_s = {:g} s (need k_c dt / gamma < 0.5); the largest value this step "
                      "allows is {:.3g}",
                      dt_s, 0.5 * gamma / dt_s),
          contact_stiffness_N_per_m);
  // So is the trap's: its linear spring is integrated exactly, but the rest of its force, k d
  // (1 - g(d)), as large as k d once the bead nears escape, is frozen over the step like the
  // contact. A trap stiffer than this relaxes within a step: its corner frequency k / (2 pi gamma)
  // lies beyond what the step resolves (1e-2 N/m at 1e-5 s gave wrong corner frequencies).
  require(trap_stiffness_N_per_m * dt_s / gamma < 0.5, "trap_stiffness_N_per_m",
          fmt::format("too stiff for dt_s = {:g} s (need k dt / gamma < 0.5, gamma = 6 pi viscosity "
                      "bead_radius); the largest value this step allows is {:.3g}",
                      dt_s, 0.5 * gamma / dt_s),
          trap_stiffness_N_per_m);
}

void OpticalTrapSceneParams::validate() const {
  trap.validate();
  require(std::isfinite(obstacle_offset_x_m) && std::isfinite(obstacle_offset_y_m), "obstacle_offset_m",
          "must be finite");
  // Apart at the start (the probe would start inside the stuck bead) and within a microscope's
  // field (the scene is a dish region of tens of micrometres).
  const double d = std::hypot(obstacle_offset_x_m, obstacle_offset_y_m);
  require(d > trap.bead_radius_m + trap.obstacle_radius_m, "obstacle_offset_x_m",
          "puts the stuck bead on the probe (need a distance above the two radii)", d);
  require(d <= 1e-3, "obstacle_offset_x_m", "must put the stuck bead within 1 mm of the probe", d);
}

OpticalTrap::OpticalTrap(const OpticalTrapParams& params) : params_(params) {
  params_.validate();
  gamma_ = 6.0 * std::numbers::pi * params_.viscosity_Pa_s * params_.bead_radius_m;
  decay_ = std::exp(-params_.trap_stiffness_N_per_m * params_.dt_s / gamma_);
  kick_ = std::sqrt(position_variance_m2() * (1.0 - decay_ * decay_));
  w_ = params_.escape_distance_m > 0.0 ? params_.escape_distance_m : params_.bead_radius_m * std::exp(0.25);
}

double OpticalTrap::escape_force_N() const { return params_.trap_stiffness_N_per_m * w_ * std::exp(-0.25); }

double OpticalTrap::corner_frequency_Hz() const {
  return params_.trap_stiffness_N_per_m / (2.0 * std::numbers::pi * gamma_);
}

double OpticalTrap::position_variance_m2() const {
  return kBoltzmann * params_.temperature_K / params_.trap_stiffness_N_per_m;
}

Eigen::Vector2d OpticalTrap::contact_force(const Eigen::Vector2d& bead_m) const {
  if (!has_obstacle_) return Eigen::Vector2d::Zero();
  const Eigen::Vector2d d = bead_m - obstacle_;
  const double dist = d.norm();
  const double overlap = params_.bead_radius_m + params_.obstacle_radius_m - dist;
  if (overlap <= 0.0 || dist <= 0.0) return Eigen::Vector2d::Zero();
  return params_.contact_stiffness_N_per_m * overlap * d / dist;
}

double OpticalTrap::hold_fraction(const Eigen::Vector2d& d) const noexcept {
  const double u = d.squaredNorm() / (w_ * w_);
  return std::exp(-0.25 * u * u);
}

Eigen::Vector2d OpticalTrap::trap_force(const OpticalTrapState& s) const {
  const Eigen::Vector2d d = s.bead_m - s.trap_m;
  return -params_.trap_stiffness_N_per_m * hold_fraction(d) * d;
}

bool OpticalTrap::try_step(OpticalTrapState& s, Rng& rng) const noexcept {
  // The linear spring -k d is integrated exactly (Ornstein-Uhlenbeck); the rest of the trap's
  // force, k d (1 - g(d)), is frozen over the step like the contact: far from
  // the trap the two cancel and the bead diffuses freely (the kick then tends to
  // sqrt(2 k_B T dt / gamma)).
  const Eigen::Vector2d d = s.bead_m - s.trap_m;
  const double k = params_.trap_stiffness_N_per_m;
  const Eigen::Vector2d release = k * (1.0 - hold_fraction(d)) * d;
  const Eigen::Vector2d fc = contact_force(s.bead_m);
  const Eigen::Vector2d eq = s.trap_m + (fc + release) / k;
  for (int a = 0; a < 2; ++a) {
    s.bead_m(a) = eq(a) + (s.bead_m(a) - eq(a)) * decay_ + kick_ * rng.normal();
  }
  return s.bead_m.allFinite();
}

void OpticalTrap::step(OpticalTrapState& s, Rng& rng) const {
  if (!try_step(s, rng)) throw ComputationFailed("optical trap: non-finite bead position");
}

}  // namespace mc::microworld
