#include "microcobot/tweezers/virtual_cube.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/tweezers/smoothstep.h"

namespace mc::tweezers {

void VirtualCubeParams::validate() const {
  require_positive(cube_width_m, "cube_width_m");
  require_non_negative(stiffness_N_per_m, "stiffness_N_per_m");
  require_positive(control_rate_Hz, "control_rate_Hz");
  require(plant_rate_Hz >= control_rate_Hz, "plant_rate_Hz", "must be >= control_rate_Hz", plant_rate_Hz);
  const double ratio = plant_rate_Hz / control_rate_Hz;
  require(std::abs(ratio - std::round(ratio)) < 1e-9, "plant_rate_Hz",
          "must be a multiple of control_rate_Hz", plant_rate_Hz);
  require_positive(lag_pole_Hz, "lag_pole_Hz");
  require(lag_zero_Hz > lag_pole_Hz, "lag_zero_Hz", "must be above lag_pole_Hz", lag_zero_Hz);
  // The compensator's zero must lie below the loop's Nyquist frequency: named by the rate, which is
  // what a caller changes (the CLI's --rate), not by the compensator's internal zero_Hz.
  if (compensator) {
    require(control_rate_Hz > 2.0 * lag_zero_Hz, "control_rate_Hz",
            fmt::format("must exceed 2 x lag_zero_Hz = {:g} Hz (the lag compensator's zero must lie below "
                        "the loop's Nyquist frequency)",
                        2.0 * lag_zero_Hz),
            control_rate_Hz);
  }
  require_positive(ramp_s, "ramp_s");
  require_positive(duration_s, "duration_s");
  require(hold_window_s > 0 && hold_window_s < duration_s - ramp_s, "hold_window_s",
          "must be > 0 and fit after the ramp", hold_window_s);
  require_positive(chatter_rel_rms, "chatter_rel_rms");
  // The work budget, before the run (docs/cli.md, "Limits").
  require_budget(duration_s * plant_rate_Hz, kMaxSimulatedSteps, "cube.plant_rate_Hz",
                 "simulated steps (duration_s x plant_rate_Hz; --rate sets plant_rate_Hz = 20 x rate)");
}

VirtualCubeRenderer::VirtualCubeRenderer(const TeleTweezParams& model, const VirtualCubeParams& cube)
    : gap_(0.5 * (model.static_opening_tip_m - cube.cube_width_m)),
      stiffness_(cube.stiffness_N_per_m),
      torque_per_newton_(model.torque_for_finger_force(1.0)),
      max_torque_(model.max_torque_N_m) {
  model.validate();
  cube.validate();
  require(cube.cube_width_m < model.static_opening_tip_m, "cube_width_m",
          "must be narrower than the static opening", cube.cube_width_m);
  const double k_max = max_renderable_stiffness(model, cube);
  require(cube.stiffness_N_per_m <= k_max, "stiffness_N_per_m",
          fmt::format(
              "too stiff for control_rate_Hz = {:g} Hz (the wall's frequency on the {:.3g} kg tip mass "
              "must stay below the loop's Nyquist frequency); the largest value this rate allows is {:.3g}",
              cube.control_rate_Hz, tip_mass(model), k_max),
          cube.stiffness_N_per_m);
  if (cube.compensator) lag_.emplace(cube.lag_pole_Hz, cube.lag_zero_Hz, cube.control_rate_Hz);
}

double VirtualCubeRenderer::update(double lever_m) noexcept {
  penetration_ = std::max(0.0, lever_m - gap_);
  wall_force_ = stiffness_ * penetration_;
  rendered_force_ = lag_ ? lag_->process(wall_force_) : wall_force_;
  // The wall pushes the tips open: negative (opening) torque, saturated at the motor's limit.
  return std::clamp(-rendered_force_ * torque_per_newton_, -max_torque_, max_torque_);
}

VirtualCubeResult simulate_virtual_cube(const TeleTweezParams& model_params, const VirtualCubeParams& cube) {
  VirtualCubeRenderer renderer(model_params, cube);
  const double dt = 1.0 / cube.plant_rate_Hz;
  const TeleTweez model(model_params, dt);
  const int sub = static_cast<int>(std::lround(cube.plant_rate_Hz / cube.control_rate_Hz));
  const auto n_ctrl = static_cast<std::size_t>(std::llround(cube.duration_s * cube.control_rate_Hz));
  VirtualCubeResult r;
  r.t_s.reserve(n_ctrl);
  r.opening_m.reserve(n_ctrl);
  r.penetration_m.reserve(n_ctrl);
  r.wall_force_N.reserve(n_ctrl);
  r.torque_N_m.reserve(n_ctrl);
  TeleTweezState s;
  Input u = Input::Zero();
  const double kf = model_params.finger_stiffness_N_per_m, cf = model_params.finger_damping_N_s_per_m;
  for (std::size_t k = 0; k < n_ctrl; ++k) {
    const double t = static_cast<double>(k) / cube.control_rate_Hz;
    u[kTorque] = renderer.update(s.q[kXL]);  // sample, compute, hold (ZOH)
    r.t_s.push_back(t);
    r.opening_m.push_back(model.tip_opening(s));
    r.penetration_m.push_back(renderer.penetration());
    r.wall_force_N.push_back(renderer.wall_force());
    r.torque_N_m.push_back(u[kTorque]);
    for (int j = 0; j < sub; ++j) {
      const double tj = t + j * dt;
      // Fingers: spring-dampers from the intended position x_op(t) to the lever (their x_l
      // terms are in K and C; the x_op terms are this input force).
      const double x = tj / cube.ramp_s;
      u[kFingerForce] = kf * cube.operator_target_m * smoothstep(x) +
                        cf * cube.operator_target_m * smoothstep_rate(x) / cube.ramp_s;
      model.step(s, u);
    }
    if (!s.q.allFinite() || !s.v.allFinite() || std::abs(s.q[kXL]) > 1.0) {
      throw ComputationFailed("virtual cube: the simulation diverged");
    }
  }
  r.max_penetration_m = *std::max_element(r.penetration_m.begin(), r.penetration_m.end());
  const auto w0 =
      static_cast<std::size_t>(std::llround((cube.duration_s - cube.hold_window_s) * cube.control_rate_Hz));
  double sum = 0, sum2 = 0;
  bool lost = false;
  for (std::size_t k = w0; k < n_ctrl; ++k) {
    sum += r.wall_force_N[k];
    sum2 += r.wall_force_N[k] * r.wall_force_N[k];
    lost = lost || r.penetration_m[k] <= 0.0;
  }
  const double n = static_cast<double>(n_ctrl - w0);
  r.mean_force_N = sum / n;
  r.oscillation_rms_N = std::sqrt(std::max(0.0, sum2 / n - r.mean_force_N * r.mean_force_N));
  if (r.mean_force_N > 0) {
    r.chatter = lost || r.oscillation_rms_N > cube.chatter_rel_rms * r.mean_force_N;
  }
  return r;
}

double max_chatter_free_stiffness(const TeleTweezParams& model, VirtualCubeParams cube, double lo, double hi,
                                  int iterations) {
  // Nothing above what the loop can render is simulated (max_renderable_stiffness()).
  require(lo > 0 && hi > lo, "stiffness range", "needs 0 < lo < hi", lo);
  hi = std::min(hi, max_renderable_stiffness(model, cube));
  require(hi > lo, "stiffness range",
          fmt::format("starts above the stiffest wall control_rate_Hz = {:g} Hz can render ({:.3g} N/m)",
                      cube.control_rate_Hz, hi),
          lo);
  auto chatters = [&](double k) {
    cube.stiffness_N_per_m = k;
    return simulate_virtual_cube(model, cube).chatter;
  };
  if (chatters(lo)) return lo;
  if (!chatters(hi)) return hi;
  for (int i = 0; i < iterations; ++i) {
    const double mid = std::sqrt(lo * hi);
    (chatters(mid) ? hi : lo) = mid;
  }
  return lo;
}

double tip_damping(const TeleTweezParams& p) {
  const double r = p.lever_per_motor_rad();
  // Motor damping c_m seen at x_l (generalized, both levers) is c_m / r^2; per tip, half.
  return p.motor_damping_N_m_s / (2.0 * r * r) + p.clamping_damping_N_s_per_m;
}

double tip_mass(const TeleTweezParams& p) {
  const double r = p.lever_per_motor_rad();
  return p.motor_inertia_kg_m2 / (2.0 * r * r) + p.lever_mass_kg;
}

double max_renderable_stiffness(const TeleTweezParams& p, const VirtualCubeParams& cube) {
  const double nyquist = std::numbers::pi * cube.control_rate_Hz;
  const double hf_gain = cube.compensator ? cube.lag_pole_Hz / cube.lag_zero_Hz : 1.0;
  return tip_mass(p) * nyquist * nyquist / hf_gain;
}

double colgate_stiffness_bound(const TeleTweezParams& p, double control_rate_Hz, double virtual_damping) {
  require_positive(control_rate_Hz, "control_rate_Hz");
  return std::max(0.0, 2.0 * (tip_damping(p) - std::abs(virtual_damping)) * control_rate_Hz);
}

}  // namespace mc::tweezers
