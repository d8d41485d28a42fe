#pragma once
/// @file
/// The two control modes of the TéléTweez (thesis section 4.3.2, Fig. 4.11):
/// - robotic mode: the tweezers' opening drives a slave gripper's opening with a scale factor,
///   and the slave's contact force comes back to the fingers scaled up;
/// - manual mode: the tweezers clamp a real object and hold a set clamping force by themselves
///   (force loop on the tip force sensor) while the operator relaxes.

#include <vector>

#include "microcobot/tweezers/teletweez.h"

namespace mc::tweezers {

struct RoboticModeParams {
  double control_rate_Hz = 1000.0;        ///< the controller's rate
  double plant_rate_Hz = 10000.0;         ///< the simulated plant's rate (a multiple of it)
  double position_scale = 0.01;           ///< slave opening change per tweezers tip opening change
  double force_scale = 2e4;               ///< finger force per slave contact force (uN -> tens of mN)
  double slave_opening_m = 100e-6;        ///< slave gripper static opening (choice)
  double slave_time_constant_s = 5e-3;    ///< slave position loop (first order, choice)
  double object_width_m = 80e-6;          ///< micro-object between the slave jaws (choice)
  double object_stiffness_N_per_m = 5.0;  ///< per jaw (choice): 10 um squeeze -> 50 uN
  double operator_target_m = 3e-3;        ///< finger aim per lever
  double ramp_s = 1.0;                    ///< the operator reaches the aim over this time
  double duration_s = 2.0;                ///< the run's length
  template <class V>
  void visit(V& v) {
    v("control_rate_Hz", control_rate_Hz);
    v("plant_rate_Hz", plant_rate_Hz);
    v("position_scale", position_scale);
    v("force_scale", force_scale);
    v("slave_opening_m", slave_opening_m);
    v("slave_time_constant_s", slave_time_constant_s);
    v("object_width_m", object_width_m);
    v("object_stiffness_N_per_m", object_stiffness_N_per_m);
    v("operator_target_m", operator_target_m);
    v("ramp_s", ramp_s);
    v("duration_s", duration_s);
  }
  void validate() const;
};

struct ManualModeParams {
  double control_rate_Hz = 1000.0;        ///< the force loop's rate
  double plant_rate_Hz = 10000.0;         ///< the simulated plant's rate (a multiple of it)
  double object_width_m = 8e-3;           ///< real object between the tips (10 mm opening)
  double object_stiffness_N_per_m = 5e3;  ///< per tip (choice: a watch part between Delrin tips)
  double object_damping_N_s_per_m = 5.0;  ///< per tip contact damping (choice)
  double set_force_N = 1.0;               ///< clamping force to hold (< 2.2 N available)
  double kp = 0.3;                        ///< force loop proportional gain [N/N] (choice)
  double ki_per_s = 5.0;                  ///< force loop integral gain [1/s] (choice)
  double operator_target_m = 3e-3;        ///< the operator pinches to grasp ...
  double grasp_s = 0.5;                   ///< ... during this time, then
  double release_s = 1.0;                 ///< relaxes the fingers from this time on
  double duration_s = 2.5;                ///< the run's length
  bool hold = true;                       ///< the force loop runs (false: plain tweezers)
  template <class V>
  void visit(V& v) {
    v("control_rate_Hz", control_rate_Hz);
    v("plant_rate_Hz", plant_rate_Hz);
    v("object_width_m", object_width_m);
    v("object_stiffness_N_per_m", object_stiffness_N_per_m);
    v("object_damping_N_s_per_m", object_damping_N_s_per_m);
    v("set_force_N", set_force_N);
    v("kp", kp);
    v("ki_per_s", ki_per_s);
    v("operator_target_m", operator_target_m);
    v("grasp_s", grasp_s);
    v("release_s", release_s);
    v("duration_s", duration_s);
    v("hold", hold);
  }
  void validate() const;
};

/// Traces of a control-mode scenario at the control rate.
struct ModeTrace {
  std::vector<double> t_s, master_opening_m, slave_opening_m, contact_force_N, finger_force_N, torque_N_m;
};

struct RoboticModeResult {
  ModeTrace trace;
  double final_slave_force_N = 0;
  double final_rendered_force_N = 0;  ///< force the motor applies at each finger
};
/// Robotic mode: the operator pinches; the slave closes on a micro-object; its force comes back.
RoboticModeResult simulate_robotic_mode(const TeleTweezParams& model, const RoboticModeParams& params);

struct ManualModeResult {
  ModeTrace trace;
  double held_force_N = 0;        ///< mean clamping force after the operator relaxed (last 0.5 s)
  double held_force_error_N = 0;  ///< max |force - set| over the last 0.5 s
};
/// Manual mode: grasp a real object, relax, the tweezers keep the set force.
ManualModeResult simulate_manual_mode(const TeleTweezParams& model, const ManualModeParams& params);

}  // namespace mc::tweezers
