#pragma once
/// @file
/// Teleoperation coupling between the masters (dual-stage haptic interface, TéléTweez) and the
/// slave (XYZ stick-slip stage, micro-gripper) of the platform (thesis §1.3, Fig. 1.12-1.13):
///
///  - position: slave XY target = offset + motion_scale x handle position. The offset is
///    re-taken whenever the coupling engages, so engaging never moves the slave; releasing the
///    clutch (indexing) lets the operator bring the hand back while the slave holds, which is
///    how a 100 mm hand workspace reaches the stage's full stroke at a 1/100 scale;
///  - Z: the operator's jog knob integrates a velocity into the Z target;
///  - gripper opening = grip_position_scale x TéléTweez tip opening (the robotic mode of §4.3.2);
///  - force: the haptic force = force_scale x slave contact force (XY), low-pass filtered, the
///    TéléTweez finger force = grip_force_scale x slave grip force, both capped;
///  - console: while the operator's console holds control, it replaces the haptic
///    master: the stage target moves at the joystick's velocity or straight to a clicked goal
///    (rate-limited), and the gripper opening is the console's; the haptic force is zero;
///  - safety: the coupling is engaged only while the deadman is held, the clutch released and the
///    haptic master's (or the console's) commands fresh (the platform's watchdog). Disengaged, the slave
///    targets freeze (the stage holds where it is) and the haptic force is zero; the gripper follows the
///    TéléTweez (or the console) only while the deadman is held and its readings are fresh, and holds
///    otherwise (nothing of the slave moves without the deadman). Whatever the input, the
///    grip force, the contact force and the floor are limited (safety_limits.h).
///
/// tick() runs on the real-time path at the haptic rate: no allocation, lock, exception or I/O.

#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "microcobot/teleop/safety_limits.h"
#include "microcobot/teleop/virtual_fixtures.h"

namespace mc::teleop {

struct TeleoperationParams {
  double motion_scale = 0.01;  ///< slave metres per hand metre (1 mm of hand -> 10 um)
  double force_scale = 1.0e4;  ///< hand newtons per slave newton (36 uN -> 0.36 N)
  double max_force_N = 2.0;    ///< cap on the haptic force (Pantograph rated 4 N)
  /// First-order low-pass on the haptic force: slave contact forces switch within a tick
  /// (stick-slip, contact changes), which a scaled rendering would turn into chatter.
  double force_filter_Hz = 30.0;
  double grip_position_scale = 0.06;  ///< gripper opening per TéléTweez tip opening (10 mm -> 600 um)
  double grip_force_scale = 100.0;    ///< TéléTweez finger newtons per slave grip newton
  double max_grip_force_N = 2.0;      ///< cap on the finger force (2.2 N available, Table 4.8)
  double max_jog_m_s = 5e-4;          ///< Z jog velocity limit
  /// Slave workspace in stage coordinates (the stroke of the 12 mm axes with a margin).
  double workspace_min_m = -5.5e-3;
  double workspace_max_m = 5.5e-3;
  double console_max_speed_m_s = 1e-3;  ///< stage speed limit of the console's commands
  /// Time constant of the haptic target's velocity feedforward (the handle is read at the
  /// operator's rate, the coupling runs ten times faster).
  double velocity_filter_s = 0.005;
  /// Shared control: the virtual fixtures' shape; which fixtures act, and how
  /// strongly, is set at run time (Teleoperation::set_fixtures).
  VirtualFixtureParams fixtures;

  template <class V>
  void visit(V& v) {
    v("motion_scale", motion_scale);
    v("force_scale", force_scale);
    v("max_force_N", max_force_N);
    v("force_filter_Hz", force_filter_Hz);
    v("grip_position_scale", grip_position_scale);
    v("grip_force_scale", grip_force_scale);
    v("max_grip_force_N", max_grip_force_N);
    v("max_jog_m_s", max_jog_m_s);
    v("workspace_min_m", workspace_min_m);
    v("workspace_max_m", workspace_max_m);
    v("console_max_speed_m_s", console_max_speed_m_s);
    v("velocity_filter_s", velocity_filter_s);
    v("fixtures", fixtures);
  }
  void validate() const;
};

/// The operator console's command (joystick/tablet teleoperation, click-to-go), in
/// the coupling's stage coordinates. The platform validates and clamps it before it gets here.
struct ConsoleInput {
  bool active = false;   ///< the console holds control: the haptic master is ignored
  bool fresh = false;    ///< its commands are fresh (the platform's watchdog)
  bool deadman = false;  ///< the console's deadman is held
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();  ///< joystick stage velocity
  bool has_goal = false;                                   ///< go to goal_m (overrides velocity)
  Eigen::Vector3d goal_m = Eigen::Vector3d::Zero();
  double goal_speed_m_s = 100e-6;  ///< speed of the straight move to the goal
  double gripper_opening_m = 0.0;
  bool has_gripper = false;  ///< false: the TéléTweez drives the gripper
  /// The gripper's release burst (microworld/release.h, shake), with the gripper and the deadman.
  bool gripper_shake = false;
  /// The rotary axis (rotary_axis.h): to theta_goal_rad at theta_speed_rad_s (has_theta_goal),
  /// else at the dial's rate theta_rate_rad_s; with this input's deadman, whether or not it holds
  /// the XYZ coupling (the haptic master has no rotation: the console's dial turns the gripper).
  bool has_theta_goal = false;
  double theta_goal_rad = 0.0;
  double theta_speed_rad_s = 0.1;
  double theta_rate_rad_s = 0.0;
};

/// What the masters and the slave report at one haptic tick.
struct TeleoperationInput {
  Eigen::Vector2d handle_m = Eigen::Vector2d::Zero();          ///< haptic handle position
  bool deadman = false;                                        ///< enable switch held
  bool clutch = false;                                         ///< indexing button pressed
  double z_jog_m_s = 0.0;                                      ///< jog knob velocity
  bool haptic_fresh = true;                                    ///< haptic master readings are fresh
  double tweezers_opening_m = 0.0;                             ///< TéléTweez tip opening
  bool tweezers_fresh = true;                                  ///< TéléTweez readings are fresh
  Eigen::Vector3d slave_position_m = Eigen::Vector3d::Zero();  ///< measured stage position
  Eigen::Vector3d contact_force_N = Eigen::Vector3d::Zero();   ///< force on the slave gripper
  double grip_force_N = 0.0;                                   ///< slave grip force
  double gripper_opening_m = 0.0;  ///< measured opening (the part's width while gripping)
  /// The slave's measurements are fresh (a remote slave that went silent is not): while they
  /// are stale the coupling disengages with no force on the masters, and the slave target is
  /// re-taken from the measured position when they return.
  bool slave_fresh = true;
  ConsoleInput console;  ///< the console, when it holds control
};

/// The coupling's commands.
struct TeleoperationOutput {
  Eigen::Vector3d slave_target_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d slave_velocity_m_s = Eigen::Vector3d::Zero();  ///< feedforward of the target
  double gripper_opening_m = 0.0;
  bool gripper_shake = false;  ///< the release burst: only from an engaged console that has the gripper
  Eigen::Vector2d haptic_force_N = Eigen::Vector2d::Zero();
  double finger_force_N = 0.0;
  bool engaged = false;
  bool stale = false;  ///< a master's readings went stale
};

class Teleoperation {
 public:
  /// Validates; `dt_s` is the haptic period. The slave starts holding at `slave_start_m`
  /// with the gripper at `gripper_start_m`.
  Teleoperation(const TeleoperationParams& params, double dt_s, const Eigen::Vector3d& slave_start_m,
                double gripper_start_m, const SafetyLimitParams& limits = {});
  /// One haptic tick. Never allocates.
  const TeleoperationOutput& tick(const TeleoperationInput& in) noexcept;
  const TeleoperationOutput& output() const noexcept { return out_; }
  const TeleoperationParams& params() const noexcept { return p_; }
  const SafetyLimits& limits() const noexcept { return limits_; }
  /// True while the last tick held the stage against an over-limit contact.
  bool contact_limited() const noexcept { return contact_limited_; }
  /// Holds the slave where it is measured (target = position, zero velocity), disengaged: the
  /// hand-back after an automatic sequence. Real-time safe.
  void hold_at(const Eigen::Vector3d& measured_m) noexcept;
  /// The highest target height from the next tick (+inf, or NaN: none), on every input path, the
  /// master's own height going with it (no wind-up): the platform's limit for a slave that rises
  /// toward the tool (the seat on the parallel positioner under the finger tips). Real-time safe.
  void set_height_ceiling(double ceiling_m) noexcept {
    ceiling_m_ = std::isnan(ceiling_m) ? std::numeric_limits<double>::infinity() : ceiling_m;
  }
  /// The lowest target height from the next tick (-inf, or NaN: none) beside the limits' own
  /// floor, the higher of the two acting, the master's height going with it: the platform's floor
  /// over a substrate that moves (the seat raised by the parallel positioner). Real-time safe.
  void set_height_floor(double floor_m) noexcept {
    floor_m_ = std::isnan(floor_m) ? -std::numeric_limits<double>::infinity() : floor_m;
  }
  /// The virtual fixtures for the coming ticks (stage coordinates; virtual_fixtures.h), on every
  /// input path. Real-time safe.
  /// A guide that moves starts again from level 0 (slewed up), and the master's target is
  /// re-taken from the slave's: a new guide never moves the slave at once.
  void set_fixtures(const FixtureSet& set) noexcept;
  const VirtualFixtures& fixtures() const noexcept { return fixtures_; }
  /// The motion scale in force (the configured one times the fixtures' gain).
  double motion_scale() const noexcept { return scale_; }
  /// The motion scale the fixtures would give at the target `xy` (stage coordinates).
  double motion_scale_at(const Eigen::Vector2d& xy) const noexcept {
    return p_.motion_scale * fixtures_.scale_gain(xy);
  }

 private:
  double clamp_workspace(double v) const noexcept;
  void console_tick(const TeleoperationInput& in) noexcept;
  /// The target in the plane under the fixtures, from `from` (slewed where they act).
  Eigen::Vector2d follow_fixtures(const Eigen::Vector2d& from) noexcept;
  /// The target's height under a height stop, from `from_z` (slewed like the plane's), then kept
  /// above the funnel at `xy`; the master's raw height never winds up below what the funnel allows.
  double follow_height(double from_z, const Eigen::Vector2d& xy) noexcept;
  /// End of a tick: without a height stop the master's raw height is the target's.
  void sync_raw_z() noexcept;
  /// The safety limits on this tick's commands (every input path).
  void apply_limits(const TeleoperationInput& in, double requested_opening_m) noexcept;

  TeleoperationParams p_;
  SafetyLimits limits_;
  double ceiling_m_ = std::numeric_limits<double>::infinity();
  double floor_m_ = -std::numeric_limits<double>::infinity();
  bool contact_limited_ = false;
  double dt_;
  TeleoperationOutput out_;
  double force_alpha_ = 1.0;     // low-pass coefficient per tick
  double velocity_alpha_ = 1.0;  // the feedforward's
  Eigen::Vector2d velocity_ff_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d force_filtered_N_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d offset_m_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d last_xy_m_ = Eigen::Vector2d::Zero();
  Eigen::Vector3d kept_from_m_ = Eigen::Vector3d::Zero();  // the target the keep-outs judge a tick from
  VirtualFixtures fixtures_;
  Eigen::Vector2d raw_xy_m_ = Eigen::Vector2d::Zero();  // the master's target before the fixtures
  double raw_z_m_ = 0.0;                                // ... and its height
  bool slewing_z_ = false;                              // the height catching up with a stop
  bool reindex_z_ = false;                              // a new height stop: raw height re-taken
  Eigen::Vector2d last_handle_m_ = Eigen::Vector2d::Zero();
  double scale_ = 0.0;                // motion scale in force
  bool slewing_ = false;              // the target catching up with the fixtures' output
  bool reindex_ = false;              // a new guide: the master's target re-taken from the slave's
  bool console_had_control_ = false;  // the haptic path re-indexes when it takes over
  bool slave_was_stale_ = false;      // re-take the target from the slave when it returns
};

}  // namespace mc::teleop
