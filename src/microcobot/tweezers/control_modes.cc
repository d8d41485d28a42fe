#include "microcobot/tweezers/control_modes.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/tweezers/smoothstep.h"

namespace mc::tweezers {

namespace {
int substeps(double plant, double control) {
  const double r = plant / control;
  require(r >= 1 && std::abs(r - std::round(r)) < 1e-9, "plant_rate_Hz",
          "must be a multiple of control_rate_Hz", plant);
  return static_cast<int>(std::lround(r));
}
void check_finite(const TeleTweezState& s, const char* what) {
  if (!s.q.allFinite() || !s.v.allFinite() || std::abs(s.q[kXL]) > 1.0) {
    throw ComputationFailed(std::string(what) + ": the simulation diverged");
  }
}
}  // namespace

void RoboticModeParams::validate() const {
  require_positive(control_rate_Hz, "control_rate_Hz");
  require_positive(plant_rate_Hz, "plant_rate_Hz");
  require_positive(position_scale, "position_scale");
  require_non_negative(force_scale, "force_scale");
  require_positive(slave_opening_m, "slave_opening_m");
  require_positive(slave_time_constant_s, "slave_time_constant_s");
  require_positive(object_width_m, "object_width_m");
  require_non_negative(object_stiffness_N_per_m, "object_stiffness_N_per_m");
  require_positive(ramp_s, "ramp_s");
  require(duration_s > ramp_s, "duration_s", "must exceed ramp_s", duration_s);
}

void ManualModeParams::validate() const {
  require_positive(control_rate_Hz, "control_rate_Hz");
  require_positive(plant_rate_Hz, "plant_rate_Hz");
  require_positive(object_width_m, "object_width_m");
  require_positive(object_stiffness_N_per_m, "object_stiffness_N_per_m");
  require_non_negative(object_damping_N_s_per_m, "object_damping_N_s_per_m");
  require_non_negative(set_force_N, "set_force_N");
  require_non_negative(kp, "kp");
  require_non_negative(ki_per_s, "ki_per_s");
  require_positive(grasp_s, "grasp_s");
  require(release_s > grasp_s, "release_s", "must come after grasp_s", release_s);
  require(duration_s > release_s + 0.5, "duration_s", "must leave 0.5 s after release_s", duration_s);
}

RoboticModeResult simulate_robotic_mode(const TeleTweezParams& mp, const RoboticModeParams& p) {
  p.validate();
  const int sub = substeps(p.plant_rate_Hz, p.control_rate_Hz);
  const double dt = 1.0 / p.plant_rate_Hz;
  const TeleTweez model(mp, dt);
  const double alpha = 1.0 - std::exp(-1.0 / (p.control_rate_Hz * p.slave_time_constant_s));
  const auto n = static_cast<std::size_t>(std::llround(p.duration_s * p.control_rate_Hz));
  RoboticModeResult r;
  TeleTweezState s;
  Input u = Input::Zero();
  double slave = p.slave_opening_m;
  const double kf = mp.finger_stiffness_N_per_m;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / p.control_rate_Hz;
    // Master -> slave: the tips' closing, scaled, is the slave's closing command.
    const double master = model.tip_opening(s);
    const double command = p.slave_opening_m - p.position_scale * (mp.static_opening_tip_m - master);
    slave += alpha * (std::max(command, 0.0) - slave);
    // Slave contact: each jaw squeezes the object by (width - opening) / 2 ...
    const double squeeze = std::max(0.0, 0.5 * (p.object_width_m - slave));
    const double fs = p.object_stiffness_N_per_m * squeeze;
    // ... and the jaws stop where the object pushes back hard enough (stiff position loop).
    // Slave -> master: the scaled force opposes the fingers.
    const double rendered = p.force_scale * fs;
    u[kTorque] = std::clamp(-mp.torque_for_finger_force(rendered), -mp.max_torque_N_m, mp.max_torque_N_m);
    r.trace.t_s.push_back(t);
    r.trace.master_opening_m.push_back(master);
    r.trace.slave_opening_m.push_back(slave);
    r.trace.contact_force_N.push_back(fs);
    r.trace.finger_force_N.push_back(-u[kTorque] / mp.torque_for_finger_force(1.0));
    r.trace.torque_N_m.push_back(u[kTorque]);
    u[kFingerForce] = kf * p.operator_target_m * smoothstep(t / p.ramp_s);
    for (int j = 0; j < sub; ++j) model.step(s, u);
    check_finite(s, "robotic mode");
  }
  r.final_slave_force_N = r.trace.contact_force_N.back();
  r.final_rendered_force_N = r.trace.finger_force_N.back();
  return r;
}

ManualModeResult simulate_manual_mode(const TeleTweezParams& mp, const ManualModeParams& p) {
  p.validate();
  require(p.object_width_m < mp.static_opening_tip_m, "object_width_m",
          "must be narrower than the static opening", p.object_width_m);
  // The object's spring acts on the tip explicitly (held over each plant step): its frequency on
  // the tip's mass must be resolved, omega h <= 0.5. Measured with `tweezers manual` (defaults,
  // damping 5 N s/m): the held force breaks from omega h ~ 0.7 (1.2e5 N/m at 10 kHz, 4.8e5 at
  // 40 kHz) and diverges by 2e6 N/m at 10 kHz; 0.5 keeps a factor of 2 in stiffness.
  const double k_max = 0.25 * mp.tip_mass_kg * p.plant_rate_Hz * p.plant_rate_Hz;
  require(
      p.object_stiffness_N_per_m <= k_max, "object_stiffness_N_per_m",
      fmt::format("too stiff for plant_rate_Hz = {:g} Hz on the {:g} kg tip (omega h = {:.3g} > 0.5); the "
                  "largest value this rate allows is {:.3g}",
                  p.plant_rate_Hz, mp.tip_mass_kg,
                  std::sqrt(p.object_stiffness_N_per_m) / std::sqrt(mp.tip_mass_kg) / p.plant_rate_Hz, k_max),
      p.object_stiffness_N_per_m);
  const int sub = substeps(p.plant_rate_Hz, p.control_rate_Hz);
  const double dt = 1.0 / p.plant_rate_Hz;
  const TeleTweez model(mp, dt);
  const double gap = 0.5 * (mp.static_opening_tip_m - p.object_width_m);
  const double kf = mp.finger_stiffness_N_per_m, cf = mp.finger_damping_N_s_per_m;
  const double tq = mp.torque_for_finger_force(1.0);
  const auto n = static_cast<std::size_t>(std::llround(p.duration_s * p.control_rate_Hz));
  ManualModeResult r;
  TeleTweezState s;
  Input u = Input::Zero();
  double integral = 0, force = 0;
  bool engaged = false;  // the loop latches on at the first contact
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / p.control_rate_Hz;
    // Tip force sensor (the resistive polymer) reads the clamping force on the object.
    const double measured = force;
    double torque = 0;
    engaged = engaged || (p.hold && measured > 0.05 * p.set_force_N);
    if (engaged) {
      // Feedforward: the set force plus the flexure's spring at the current closing; PI on the error.
      const double error = p.set_force_N - measured;
      integral += error / p.control_rate_Hz;
      const double f_cmd =
          p.set_force_N + mp.clamping_stiffness_N_per_m * s.q[kXL] + p.kp * error + p.ki_per_s * integral;
      torque = std::clamp(f_cmd * tq, -mp.max_torque_N_m, mp.max_torque_N_m);
    }
    u[kTorque] = torque;
    r.trace.t_s.push_back(t);
    r.trace.master_opening_m.push_back(model.tip_opening(s));
    r.trace.slave_opening_m.push_back(p.object_width_m);
    r.trace.contact_force_N.push_back(measured);
    r.trace.finger_force_N.push_back(0);
    r.trace.torque_N_m.push_back(torque);
    double finger_net = 0;
    for (int j = 0; j < sub; ++j) {
      const double tj = t + j * dt;
      // Fingers pinch towards the target, then relax: a relaxed finger rests on the lever and
      // pushes nothing (its spring-damper terms in K, C are cancelled).
      double ff;
      if (tj < p.release_s) {
        ff = kf * p.operator_target_m * smoothstep(tj / p.grasp_s);
      } else {
        ff = kf * s.q[kXL] + cf * s.v[kXL];
      }
      const double pen = s.q[kXCl] - gap;
      force = pen > 0
                  ? std::max(0.0, p.object_stiffness_N_per_m * pen + p.object_damping_N_s_per_m * s.v[kXCl])
                  : 0.0;
      finger_net = ff - kf * s.q[kXL] - cf * s.v[kXL];
      u[kFingerForce] = ff;
      u[kTipForce] = -force;
      model.step(s, u);
    }
    r.trace.finger_force_N.back() = finger_net;
    check_finite(s, "manual mode");
  }
  const auto w0 = static_cast<std::size_t>(std::llround((p.duration_s - 0.5) * p.control_rate_Hz));
  double sum = 0;
  for (std::size_t k = w0; k < n; ++k) {
    sum += r.trace.contact_force_N[k];
    r.held_force_error_N =
        std::max(r.held_force_error_N, std::abs(r.trace.contact_force_N[k] - p.set_force_N));
  }
  r.held_force_N = sum / static_cast<double>(n - w0);
  return r;
}

}  // namespace mc::tweezers
