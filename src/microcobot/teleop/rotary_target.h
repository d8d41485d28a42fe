#pragma once
/// @file
/// The rotary axis' command (motion/rotary_axis.h): the console's rotation goal (or rate) moved at
/// a bounded slew, only while the console's deadman is held and its commands are fresh;
/// otherwise the target stays where it is and the axis holds there. Never allocates; noexcept.

#include "microcobot/motion/rotary_axis.h"
#include "microcobot/teleop/teleoperation.h"

namespace mc::teleop {

class RotaryTarget {
 public:
  /// `dt_s` is the tick; the target's travel is [min_rad, max_rad] (the axis' end stops, with a
  /// margin). Throws mc::InvalidParams.
  RotaryTarget(const motion::RotaryAxisParams& params, double dt_s, double start_rad, double min_rad,
               double max_rad);
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
  motion::RotaryAxisParams p_;
  double dt_s_, target_, velocity_ = 0.0, min_, max_;
  double raw_;  // the dial's own yaw (the target without the stop)
  bool stop_on_ = false;
  double stop_rad_ = 0.0, stop_goal_level_ = 0.0, stop_level_ = 0.0, capture_rad_ = 0.02, level_rate_ = 2.0;
};

}  // namespace mc::teleop
