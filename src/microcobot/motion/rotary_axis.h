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

#include <cmath>

namespace mc::motion {

struct RotaryAxisParams {
  bool enabled = true;  ///< the platform has the rotary axis under its gripper
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

}  // namespace mc::motion
