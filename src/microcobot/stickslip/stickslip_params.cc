#include "microcobot/stickslip/stickslip_params.h"

#include <array>
#include <cmath>

#include <algorithm>

#include <fmt/format.h>

#include "microcobot/core/error.h"

namespace mc::stickslip {

void SliderParams::validate() const {
  require_positive(mass_kg, "slider.mass_kg");
  require_positive(stroke_m, "slider.stroke_m");
  require(std::isfinite(initial_position_m) && std::abs(initial_position_m) <= 0.5 * stroke_m,
          "slider.initial_position_m", "must lie between the end stops (|x| <= stroke_m / 2)",
          initial_position_m);
  require(std::isfinite(load_force_N), "slider.load_force_N", "must be finite", load_force_N);
}

void IntegratorParams::validate() const {
  require(std::isfinite(dt_s) && dt_s > 0.0 && dt_s <= 1e-4, "integrator.dt_s", "must be in (0, 1e-4] s",
          dt_s);
  require(substeps >= 1 && substeps <= 1000, "integrator.substeps", "must be in [1, 1000]", substeps);
  require_positive(substep_edge_V, "integrator.substep_edge_V");
  require_non_negative(substep_strain_fraction, "integrator.substep_strain_fraction");
  require_positive(substep_ringing_m, "integrator.substep_ringing_m");
}

void StickSlipParams::validate() const {
  pe.validate();
  hysteresis.validate();
  friction.validate();
  slider.validate();
  breakaway.validate();
  drive.validate();
  integrator.validate();
  validate_step(integrator.dt_s);
}

const double StickSlipParams::kMaxOmegaStep = 1.6;

double StickSlipParams::max_reaction_loop_gain(double dt_s) { return 0.75 * std::pow(dt_s / 1e-6, -0.6); }

double StickSlipParams::stick_omega_rad_s(int i) const {
  const double c = i == 0 ? friction.mass_fraction_a : 1.0 - friction.mass_fraction_a;
  const double rho0 = i == 0 ? friction.rho0_a_N_m : friction.rho0_b_N_m;
  return std::sqrt(rho0 / slider.mass_kg + 2.0 * friction.coupling_stiffness_N_m / (c * slider.mass_kg));
}

void StickSlipParams::validate_step(double dt_s) const {
  if (!slider.attached) return;  // no contact: the PE's modes are discretized exactly
  const double w_max = kMaxOmegaStep / dt_s;
  const double ms = slider.mass_kg;
  const double kc = friction.coupling_stiffness_N_m;
  const std::array<double, 2> c = {friction.mass_fraction_a, 1.0 - friction.mass_fraction_a};
  const char* names[2] = {"friction.rho0_a_N_m", "friction.rho0_b_N_m"};
  const std::array<double, 2> rho0 = {friction.rho0_a_N_m, friction.rho0_b_N_m};
  // 1. Verlet on the slider parts: omega_i h <= kMaxOmegaStep.
  for (int i = 0; i < 2; ++i) {
    if (stick_omega_rad_s(i) * dt_s <= kMaxOmegaStep) continue;
    const double largest_rho0 = ms * w_max * w_max - 2.0 * kc / c[i];
    if (largest_rho0 > 0.0 && rho0[i] > largest_rho0) {
      throw InvalidParams(
          names[i],
          fmt::format("contact mode too stiff for the step integrator.dt_s = {:g} s (omega h = {:.3g} "
                      "> {:g}); the largest value this step allows is {:.3g}",
                      dt_s, stick_omega_rad_s(i) * dt_s, kMaxOmegaStep, largest_rho0),
          rho0[i]);
    }
    const double largest_kc = (w_max * w_max - rho0[i] / ms) * c[i] * ms / 2.0;
    throw InvalidParams(
        "friction.coupling_stiffness_N_m",
        fmt::format("too stiff for the step integrator.dt_s = {:g} s (omega h = {:.3g} > {:g}); "
                    "the largest value this step allows is {:.3g}",
                    dt_s, stick_omega_rad_s(i) * dt_s, kMaxOmegaStep, std::max(largest_kc, 0.0)),
        kc);
  }
  // 2. The lagged friction reaction on the PE: loop gain sum c_i rho0_i (1/K_pa + 1/K_pb).
  const double compliance = 1.0 / pe.stiffness_a_N_m + 1.0 / pe.stiffness_b_N_m;
  const double gain = (c[0] * rho0[0] + c[1] * rho0[1]) * compliance;
  const double max_gain = max_reaction_loop_gain(dt_s);
  if (gain > max_gain) {
    const int i = c[0] * rho0[0] >= c[1] * rho0[1] ? 0 : 1;
    const double largest = (max_gain / compliance - c[1 - i] * rho0[1 - i]) / c[i];
    throw InvalidParams(
        names[i],
        fmt::format("contact too stiff for the piezo element at the step integrator.dt_s = {:g} s "
                    "(loop gain (c_a rho0_a + c_b rho0_b)(1/K_pa + 1/K_pb) = {:.3g} > {:.3g}); the "
                    "largest value this step allows is {:.3g}",
                    dt_s, gain, max_gain, std::max(largest, 0.0)),
        rho0[i]);
  }
}

StickSlipParams::PhysicalBounds StickSlipParams::physical_bounds() const {
  // max |H(U)| over the amplifier's range: the PI operator's output for a monotone ramp to
  // the extreme voltage (the largest the hysteresis can reach from rest).
  auto reach = [&](double u_end) {
    auto st = make_pi_state(hysteresis, 0.0);
    double out = 0.0;
    for (int k = 1; k <= 64; ++k) out = std::max(out, std::abs(pi_update(hysteresis, st, u_end * k / 64.0)));
    return out;
  };
  const double h_max = std::max(reach(drive.max_V), reach(drive.min_V));
  return {3.0 * std::abs(pe.static_gain_m_V) * std::max(h_max, 1.0), 0.5 * slider.stroke_m * 1.02};
}

void StickSlipParams::check_physical_bounds(const PhysicalBounds& bounds, double x1_m, double x2_m,
                                            double t_s, const std::string& where) const {
  const double x1_bound = bounds.x1_m;
  if (!std::isfinite(x1_m) || std::abs(x1_m) > x1_bound) {
    throw ComputationFailed(
        fmt::format("{}: the PE displacement {:.3g} m at t = {:g} s exceeds its physical "
                    "bound {:.3g} m (3 g max|H(U)|): the simulation is unstable; "
                    "reduce integrator.dt_s or check the contact parameters",
                    where, x1_m, t_s, x1_bound));
  }
  const double x2_bound = bounds.x2_m;
  if (!std::isfinite(x2_m) || std::abs(x2_m) > x2_bound) {
    throw ComputationFailed(
        fmt::format("{}: the slider position {:.3g} m at t = {:g} s is beyond its end stops "
                    "(+-{:g} m): the simulation is unstable",
                    where, x2_m, t_s, 0.5 * slider.stroke_m));
  }
}

}  // namespace mc::stickslip
