#pragma once
/// @file
/// Coordinated XYZ paths: straight lines and circular arcs in 3-D, with the three axes
/// synchronised by one path parameter, the arc length s(t). s(t) is a trapezoidal profile under
/// the path's velocity and acceleration limits smoothed by a moving average of length
/// T_j = a_max / j_max, which bounds the jerk by j_max while keeping |v| <= v_max and
/// |a| <= a_max (a convolution of a box with the trapezoid's acceleration), and keeps both ends
/// at rest. On an arc of radius R the speed is also bounded by the centripetal acceleration:
/// v <= sqrt(a_max R / 2) (half the budget left to the tangential part). The profile is sampled at
/// construction (allocates); sample() and point_at() never allocate. distance_to_path() is the
/// path deviation: the distance from a point to the nearest point of the ideal path.

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "microcobot/motion/reference.h"

namespace mc::motion {

struct PathLimits {
  double max_velocity_m_s = 200e-6;     ///< the path's speed limit
  double max_acceleration_m_s2 = 2e-3;  ///< its acceleration limit
  double max_jerk_m_s3 = 0.2;           ///< jerk limit: T_j = a_max / j_max = 10 ms by default

  template <class V>
  void visit(V& v) {
    v("max_velocity_m_s", max_velocity_m_s);
    v("max_acceleration_m_s2", max_acceleration_m_s2);
    v("max_jerk_m_s3", max_jerk_m_s3);
  }
  void validate() const;
};

/// One axis' reference on the path at a time.
struct PathSample {
  Eigen::Vector3d x_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d a_m_s2 = Eigen::Vector3d::Zero();
  double s_m = 0.0;  ///< arc length done
};

class PathGenerator {
 public:
  /// A straight line from `from_m` to `to_m`.
  static PathGenerator line(const Eigen::Vector3d& from_m, const Eigen::Vector3d& to_m, const PathLimits& lim,
                            double sample_s = 1e-4);
  /// An arc starting at `from_m` around the axis through `center_m` along `axis` (right hand),
  /// by `angle_rad` (may be negative; |angle| <= 2 pi).
  static PathGenerator arc(const Eigen::Vector3d& from_m, const Eigen::Vector3d& center_m,
                           const Eigen::Vector3d& axis, double angle_rad, const PathLimits& lim,
                           double sample_s = 1e-4);

  double length_m() const noexcept { return length_; }
  double duration_s() const noexcept { return duration_; }
  /// The path point at arc length s (clamped to [0, L]). Never allocates.
  Eigen::Vector3d point_at(double s_m) const noexcept;
  /// Unit tangent and curvature vector (d2p/ds2) at s. Never allocates.
  Eigen::Vector3d tangent_at(double s_m) const noexcept;
  Eigen::Vector3d curvature_at(double s_m) const noexcept;
  /// Position, velocity and acceleration of the three axes at time t (clamped). Never allocates.
  PathSample sample(double t_s) const noexcept;
  /// Distance from `p_m` to the ideal path (nearest point of the whole line or arc).
  double distance_to_path(const Eigen::Vector3d& p_m) const noexcept;
  /// The speed bound used along the path (v_max, or the arc's centripetal bound).
  double path_velocity_m_s() const noexcept { return v_path_; }

 private:
  PathGenerator() = default;
  void build_profile(const PathLimits& lim, double sample_s);
  bool is_arc_ = false;
  Eigen::Vector3d p0_ = Eigen::Vector3d::Zero(), dir_ = Eigen::Vector3d::UnitX();
  Eigen::Vector3d c_ = Eigen::Vector3d::Zero(), u_ = Eigen::Vector3d::UnitX(), w_ = Eigen::Vector3d::UnitY();
  double radius_ = 0.0, angle_ = 0.0, length_ = 0.0, duration_ = 0.0, v_path_ = 0.0, h_ = 1e-4;
  std::vector<double> s_, v_, a_;  ///< s(t), s'(t), s''(t) on a grid of h_
};

}  // namespace mc::motion
