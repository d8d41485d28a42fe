#pragma once
/// @file
/// The rotary axis under the gripper: the stage's stick-slip actuator (thesis
/// ch. 2) driving a rotor through its friction contact at radius r, so that a gripped part can be
/// turned to its slot. The model is the linear one in angular units: with the rotor's arc
/// s = r theta at the contact, the slider's equation m s'' = F(u, s) (eq. 2.1-2.9 of the thesis)
/// is J theta'' = r F(u, r theta) with J = m r^2: the same actuator, the same step map, the
/// same controllers, on the arc. Its angle is theta = home + s / r; its travel is the actuator's
/// stroke seen as an arc, +-stroke / (2 r) (the gripper's cables keep a real one within a turn
/// anyway). Defaults and their sources: docs/parameters.md, "Rotary axis".
///
/// Like the other axes, the platform parks it once it has arrived (platform_config.h,
/// stage.park_after_s).
///
/// RotaryTarget is its command: the console's rotation goal (or rate) moved at a bounded slew,
/// only while the console's deadman is held and its commands are fresh; otherwise the target
/// stays where it is and the axis holds there. Never allocates; noexcept.

#include "microcobot/control/teleoperation.h"

namespace mc::control {

struct RotaryAxisParams {
  bool enabled = true;
  /// The friction drive's contact radius on the rotor: 1 nm of the actuator's slider is
  /// 1 / radius_m rad of the rotor (5 mm: 0.2 urad per nm; the stage's 12 mm stroke is +-69 deg).
  double radius_m = 5e-3;
  /// The target's slew limit: 0.16 rad/s is 800 um/s of arc, the top of the tracking
  /// controller's validated speeds (docs/benchmarks.md, "Tracking validation").
  double max_speed_rad_s = 0.16;
  double home_rad = 0.0;  ///< the gripper's yaw when the axis is at 0 (mid-stroke)

  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("radius_m", radius_m);
    v("max_speed_rad_s", max_speed_rad_s);
    v("home_rad", home_rad);
  }
  /// Throws mc::InvalidParams naming the field.
  void validate() const;
  /// The angle at arc `s_m`, and back.
  double angle_rad(double s_m) const noexcept { return home_rad + s_m / radius_m; }
  double arc_m(double angle_rad) const noexcept { return (angle_rad - home_rad) * radius_m; }
};

class RotaryTarget {
 public:
  /// `dt_s` is the tick; the target's travel is [min_rad, max_rad] (the axis' end stops, with a
  /// margin). Throws mc::InvalidParams.
  RotaryTarget(const RotaryAxisParams& params, double dt_s, double start_rad, double min_rad, double max_rad);
  /// One tick of the console's rotation command: towards theta_goal_rad at theta_speed_rad_s
  /// (has_theta_goal), else at theta_rate_rad_s, both within the slew limit; only while
  /// `console.deadman && console.fresh`, otherwise the target stays (velocity 0).
  void tick(const ConsoleInput& console) noexcept;
  /// The target where the axis is measured, at rest: the hand-back after an automatic sequence,
  /// and what a released deadman leaves (the axis holds). Real-time safe.
  void hold_at(double measured_rad) noexcept;
  /// A yaw stop (shared control of a turn, virtual_fixtures.h's height stop on the dial): with the
  /// dial's own yaw raw and e = raw - stop, the target goes to stop + (1 - b w(|e|)) e, w = 1
  /// within `capture_rad` falling to 0 at twice it, b the stop's level slewed at `level_rate_1_s`
  /// from 0 whenever the stop moves, so that installing it never jumps the target; towards that at
  /// most at the slew limit. Rate commands only (a goal is exact already). Real-time safe.
  void set_stop(bool on, double stop_rad, double level, double capture_rad, double level_rate_1_s) noexcept;
  double target_rad() const noexcept { return target_; }
  double velocity_rad_s() const noexcept { return velocity_; }
  double min_rad() const noexcept { return min_; }
  double max_rad() const noexcept { return max_; }

 private:
  RotaryAxisParams p_;
  double dt_s_, target_, velocity_ = 0.0, min_, max_;
  double raw_;  // the dial's own yaw (the target without the stop)
  bool stop_on_ = false;
  double stop_rad_ = 0.0, stop_goal_level_ = 0.0, stop_level_ = 0.0, capture_rad_ = 0.02, level_rate_ = 2.0;
};

}  // namespace mc::control
