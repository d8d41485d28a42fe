#pragma once
/// @file
/// The virtual-environment application of the TéléTweez (thesis section 4.5.3, Fig. 4.27-4.28):
/// a virtual cube between the tips, narrower than the static opening, rendered as a spring on the
/// penetration by a sampled controller (zero-order hold), optionally through the lag compensator;
/// the operator's fingers pinch as spring-dampers; the motor torque saturates.
///
/// Chatter criterion (docs/concepts/teletweez.md): during the hold window at the end of the pinch, the
/// rendered wall force oscillates with an rms above `chatter_rel_rms` of its mean, or the tips
/// leave the cube (penetration <= 0 at a control sample) although the operator keeps pinching.

#include <optional>
#include <vector>

#include "microcobot/tweezers/lag_compensator.h"
#include "microcobot/tweezers/teletweez.h"

namespace mc::tweezers {

struct VirtualCubeParams {
  double cube_width_m = 6e-3;       ///< narrower than the 10 mm static opening (choice)
  double stiffness_N_per_m = 2e3;   ///< wall stiffness K per tip
  double control_rate_Hz = 1000.0;  ///< PIC32 loop rate: not given in the thesis (choice, docs)
  double plant_rate_Hz = 20000.0;   ///< simulation rate of the mechanics (continuous stand-in)
  bool compensator = true;          ///< the lag compensator of Fig. 4.27
  double lag_pole_Hz = 1.0;         ///< w_p (choice, < 100 Hz; swept in docs/concepts/teletweez.md)
  double lag_zero_Hz = 10.0;        ///< w_z (choice, < 100 Hz): high-frequency gain 0.1
  double operator_target_m = 6e-3;  ///< where the fingers aim (per lever, at the finger contact)
  double ramp_s = 0.4;              ///< the pinch ramps to the target in this time
  double duration_s = 3.0;          ///< simulated time
  double hold_window_s = 1.0;       ///< last part of the run where chatter is judged
  double chatter_rel_rms = 0.05;    ///< oscillation rms / mean force above which it chatters

  template <class V>
  void visit(V& v) {
    v("cube_width_m", cube_width_m);
    v("stiffness_N_per_m", stiffness_N_per_m);
    v("control_rate_Hz", control_rate_Hz);
    v("plant_rate_Hz", plant_rate_Hz);
    v("compensator", compensator);
    v("lag_pole_Hz", lag_pole_Hz);
    v("lag_zero_Hz", lag_zero_Hz);
    v("operator_target_m", operator_target_m);
    v("ramp_s", ramp_s);
    v("duration_s", duration_s);
    v("hold_window_s", hold_window_s);
    v("chatter_rel_rms", chatter_rel_rms);
  }
  void validate() const;
};

/// The real-time renderer (what runs on the PIC32): sensed lever position in, motor torque out.
/// Construction allocates; update() never does.
class VirtualCubeRenderer {
 public:
  VirtualCubeRenderer(const TeleTweezParams& model, const VirtualCubeParams& cube);
  /// One control period: `lever_m` is the measured closing of each lever at the finger contact
  /// (strain gauges). Returns the motor torque to hold until the next sample.
  double update(double lever_m) noexcept;
  double penetration() const { return penetration_; }        ///< [m], per tip
  double wall_force() const { return wall_force_; }          ///< K * penetration [N], per tip
  double rendered_force() const { return rendered_force_; }  ///< after the compensator [N]
  /// Closing of each tip at which it touches the cube.
  double contact_closing() const { return gap_; }

 private:
  double gap_, stiffness_, torque_per_newton_, max_torque_;
  std::optional<LagCompensator> lag_;
  double penetration_ = 0, wall_force_ = 0, rendered_force_ = 0;
};

struct VirtualCubeResult {
  bool chatter = false;
  double max_penetration_m = 0;
  double oscillation_rms_N = 0;
  double mean_force_N = 0;  ///< mean rendered wall force in the hold window
  /// Traces at the control rate.
  std::vector<double> t_s, opening_m, penetration_m, wall_force_N, torque_N_m;
};

/// Simulates one pinch of the virtual cube. Throws ComputationFailed on divergence.
VirtualCubeResult simulate_virtual_cube(const TeleTweezParams& model, const VirtualCubeParams& cube);

/// Largest chatter-free stiffness in [lo, hi] (bisection on a log scale, `iterations` halvings),
/// with the cube's other settings; hi is capped at max_renderable_stiffness(). Returns lo if even
/// lo chatters, the (capped) hi if it does not.
double max_chatter_free_stiffness(const TeleTweezParams& model, VirtualCubeParams cube, double lo, double hi,
                                  int iterations = 14);

/// Colgate's passivity bound for a sampled virtual wall, b > K T / 2 + |B| [Colgate 1994]:
/// K_max = 2 (b - |B|) / T with b the device's physical damping at each tip (motor damping
/// reflected through the screw and the transmission, plus the flexure; the operator excluded)
/// and B = 0 (the cube is a pure spring).
double colgate_stiffness_bound(const TeleTweezParams& model, double control_rate_Hz,
                               double virtual_damping = 0.0);
/// The physical damping b of the device at each tip [N s/m].
double tip_damping(const TeleTweezParams& model);
/// The mass the rendered torque moves at each tip [kg]: the motor's inertia reflected to a tip
/// (as tip_damping() reflects its damping) plus the lever. A lower bound (the screw, support and
/// tip are left out), so the stiffness limit below errs on the safe side.
double tip_mass(const TeleTweezParams& model);
/// The stiffest wall the sampled renderer can represent: the wall's frequency on tip_mass(),
/// sqrt(K_hf / m), must stay below the loop's Nyquist frequency pi f_control, where K_hf is the
/// stiffness rendered at high frequencies (K, or K omega_p / omega_z through the lag
/// compensator). Beyond it a simulated wall's motion is an artefact of the sampling (aliased),
/// and the wall force grows without bound (1e308 N/m gave forces of 2e303 N and a false
/// "no chatter"). VirtualCubeRenderer refuses a stiffer wall (InvalidParams naming
/// stiffness_N_per_m and this limit).
double max_renderable_stiffness(const TeleTweezParams& model, const VirtualCubeParams& cube);

}  // namespace mc::tweezers
