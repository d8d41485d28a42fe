#pragma once
/// @file
/// Point-to-point moves of the parallel positioner's platform along a straight line in pose space
/// (docs/concepts/parallel-positioner.md, "Pose control"), and the check that refuses a move
/// before anything moves.
///
/// Path. A tool point c of the platform (given in {P}; the platform frame's origin, the top
/// plate's centre, by default) moves on the segment between its start and goal positions, and the
/// platform turns about the single fixed axis that takes the start orientation to the goal's, at a
/// rate proportional to the tool point's progress (the geodesic of SO(3)):
///   x_c(s) = x_c0 + s (x_c1 - x_c0),          x_c = R c + d,
///   R(s)   = R_0 exp(s [omega]x),              omega = log(R_0^T R_1) (axis-angle, |omega| <= pi),
///   d(s)   = x_c(s) - R(s) c,                  s in [0, 1].
/// So the tool point's path is the straight line and the orientation's the shortest rotation,
/// both parametrised by the same s: neither leads the other.
///
/// Time profile. s(t) is a trapezoid (or triangle when the cruise is not reached) under
///   s' <= min(v_max / |x_c1 - x_c0|, w_max / |omega|),  s'' <= min(a_max / |dx|, alpha_max / |omega|),
/// so the tool point's speed and the platform's angular rate stay within their limits; the six
/// legs follow q(t) = IK(T(s(t))), all on the same s(t) (synchronised, they start and end
/// together). Leg velocity and acceleration (the trackers' feedforward) are
///   q' = q_s s',  q'' = q_ss s'^2 + q_s s'',
/// with q_s, q_ss the central differences of IK over s (h = 1e-4).
///
/// Refusal. Before a move the start, the goal and poses along the line are checked
/// (parallel_workspace.h: finite, every leg closes, conditioning, strokes, passive joints), at
/// spacings of at most sample_length_m of the tool point's path and sample_angle_rad of rotation
/// (and at least min_samples). The leg coordinates and joint angles are smooth functions of s on
/// the reachable set, so between two samples h apart a quantity f within its limit at both can
/// exceed the limit by at most h^2 max|f''| / 8: for 10 um and 1 mrad spacings and the legs'
/// curvature (~lever^2 / r ~ 0.05 m/rad^2 at a 30 mm lever and r = 20 mm) that is below 10 nm of
/// stroke, far within the positioners' own stopping distance. The samples also bound the legs'
/// peak speed |q_s| max s' (refused above max_leg_speed_m_s).

#include <string>

#include "microcobot/motion/parallel_kinematics.h"
#include "microcobot/motion/parallel_workspace.h"
#include "microcobot/motion/pose.h"

namespace mc::motion {

struct PoseMoveLimits {
  /// v_max: the tool point's speed. 100 um/s: the SmarPod class's closed-loop scanning speeds and
  /// one leg's comfortable tracking speed (TrackingParams: edges every ~2 um at ~50 Hz).
  double max_speed_m_s = 100e-6;
  /// w_max: the platform's angular rate; 1 deg/s turns the platform's joints (r = 20 mm) at
  /// 350 um/s, the legs within max_leg_speed_m_s.
  double max_angular_speed_rad_s = 0.017453292519943295;
  /// a_max: 1 mm/s^2, the cruise reached after 5 um at 100 um/s (the contact is not rung).
  double max_acceleration_m_s2 = 1e-3;
  /// alpha_max: 10 deg/s^2, the cruise reached after 0.05 deg.
  double max_angular_acceleration_rad_s2 = 0.17453292519943295;
  /// Refused when a leg would need more than this: the tracking controller's edge envelope
  /// (TrackingParams::sprint_velocity_m_s, ~1.2 mm/s) with a margin.
  double max_leg_speed_m_s = 800e-6;
  /// The refusal check's spacing along the path (header).
  double sample_length_m = 10e-6;
  double sample_angle_rad = 1e-3;
  int min_samples = 16;
  /// The tool point c in {P}, x [m].
  double tool_x_m = 0.0;
  /// The tool point c in {P}, y [m].
  double tool_y_m = 0.0;
  /// The tool point c in {P}, z [m].
  double tool_z_m = 0.0;

  template <class V>
  void visit(V& v) {
    v("max_speed_m_s", max_speed_m_s);
    v("max_angular_speed_rad_s", max_angular_speed_rad_s);
    v("max_acceleration_m_s2", max_acceleration_m_s2);
    v("max_angular_acceleration_rad_s2", max_angular_acceleration_rad_s2);
    v("max_leg_speed_m_s", max_leg_speed_m_s);
    v("sample_length_m", sample_length_m);
    v("sample_angle_rad", sample_angle_rad);
    v("min_samples", min_samples);
    v("tool_x_m", tool_x_m);
    v("tool_y_m", tool_y_m);
    v("tool_z_m", tool_z_m);
  }
  /// Throws mc::InvalidParams naming the field.
  void validate() const;
  Eigen::Vector3d tool_m() const { return {tool_x_m, tool_y_m, tool_z_m}; }
};

/// The legs' reference at one instant.
struct LegReference {
  LegCoordinates q = LegCoordinates::Zero();
  LegCoordinates v = LegCoordinates::Zero();  ///< [m/s]
  LegCoordinates a = LegCoordinates::Zero();  ///< [m/s^2]
};

/// How far a platform pose lies from the move's path: the tool point's distance from the segment
/// and the rotation angle from the nearest orientation of the path (at s* = the projection of
/// log(R_0^T R) on omega, clamped to [0, 1]; exact to first order in the deviation).
struct PathDeviation {
  double position_m = 0.0;
  double rotation_rad = 0.0;
};

class PoseTrajectory {
 public:
  /// The path from `start` to `goal` under `limits` (validated). Does not check reachability
  /// (check_move() does). Throws InvalidInput when a pose is not finite.
  PoseTrajectory(const PlatformTransform& start, const PlatformTransform& goal, const PoseMoveLimits& limits);

  /// The pose at path parameter s in [0, 1] (clamped). Never allocates.
  PlatformTransform at(double s) const noexcept;
  /// s, s', s'' at time t from the start (0 before, 1 after the end). Never allocates.
  void profile(double t_s, double& s, double& s_dot, double& s_ddot) const noexcept;
  /// The legs' reference at time t (IK of at(s(t)) and its derivatives); false when IK fails
  /// (a move that passed check_move() never does). Never allocates.
  bool legs_at(const ParallelKinematics& k, double t_s, LegReference& out) const noexcept;
  /// The deviation of `T` from the path. Never allocates.
  PathDeviation deviation(const PlatformTransform& T) const noexcept;

  double duration_s() const noexcept { return duration_; }
  double length_m() const noexcept { return length_; }       ///< |x_c1 - x_c0|
  double angle_rad() const noexcept { return angle_; }       ///< |omega|
  double peak_s_dot() const noexcept { return s_dot_max_; }  ///< the cruise s' (or the triangle's peak)
  const PlatformTransform& start() const noexcept { return start_; }
  const PlatformTransform& goal() const noexcept { return goal_; }
  const PoseMoveLimits& limits() const noexcept { return lim_; }
  /// The tool point's position at s, {H}.
  Eigen::Vector3d tool_point(double s) const noexcept;

 private:
  PoseMoveLimits lim_;
  PlatformTransform start_, goal_;
  Eigen::Vector3d c_, xc0_, dx_, omega_;
  double length_ = 0.0, angle_ = 0.0;
  double s_dot_max_ = 0.0, s_ddot_max_ = 0.0, t_acc_ = 0.0, t_cruise_ = 0.0, duration_ = 0.0;
};

/// Why a move would be refused: the first failing pose along the line (start, goal, then the
/// samples in order of s), or a leg's speed; ok() when it may run.
struct MoveCheck {
  bool ok = true;
  std::string reason;  ///< one line, e.g. "pose at s = 0.42 (...) unreachable: stroke limit: ..."
  Reach reach = Reach::kReachable;
  int samples = 0;  ///< poses checked along the line
  double peak_leg_speed_m_s = 0.0;
};
MoveCheck check_move(const ParallelKinematics& k, const PoseTrajectory& traj);

}  // namespace mc::motion
