#pragma once
/// @file
/// Kinematics of the Pantograph (thesis §3.3.1, Fig. 3.4a; [Campion 2005b]): a planar
/// five-bar linkage with two motors on the base at (-d/2, 0) and (+d/2, 0), proximal links of
/// length l_p, distal links of length l_d joined at the handle. The Haptuator's axis is the
/// handle's y axis (Fig. 3.9).

#include <Eigen/Dense>

#include "microcobot/core/params.h"

namespace mc::haptics {

/// Geometry of the five-bar. Defaults: a desktop Pantograph with a ~100 x 160 mm workspace
/// (Table 3.2); the thesis gives no link lengths, so these are a documented choice.
struct PantographParams {
  double base_separation_m = 0.040;    ///< distance between the two motor axes
  double proximal_m = 0.090;           ///< proximal link length (motor to elbow)
  double distal_m = 0.120;             ///< distal link length (elbow to handle)
  double theta_min_rad = -0.35;        ///< joint limits of both motors (from the +x axis)
  double theta_max_rad = 3.49;         ///< (the upper joint limit)
  double min_transmission_rad = 0.35;  ///< minimum angle between distal links (singularity margin)

  template <class V>
  void visit(V& v) {
    v("base_separation_m", base_separation_m);
    v("proximal_m", proximal_m);
    v("distal_m", distal_m);
    v("theta_min_rad", theta_min_rad);
    v("theta_max_rad", theta_max_rad);
    v("min_transmission_rad", min_transmission_rad);
  }
  void validate() const;
};

/// Five-bar kinematics: q = (theta_1, theta_2) motor angles (rad, left and right motor,
/// measured from the +x axis), x = (x, y) handle position (m).
class Pantograph {
 public:
  explicit Pantograph(const PantographParams& params);
  const PantographParams& params() const { return params_; }

  /// Forward kinematics: the handle at the intersection of the two distal circles, on the
  /// side away from the base (y larger). Returns false if the circles do not intersect.
  bool forward(const Eigen::Vector2d& q, Eigen::Vector2d& x) const;
  /// Inverse kinematics ("elbows out" branch matching forward()). False if unreachable.
  bool inverse(const Eigen::Vector2d& x, Eigen::Vector2d& q) const;
  /// Jacobian dx/dq at q (analytic, from the loop-closure constraints). False at a singularity.
  bool jacobian(const Eigen::Vector2d& q, Eigen::Matrix2d& j) const;
  /// Motor torques that render force `f` (N) at the handle: tau = J^T f (virtual work).
  bool torques(const Eigen::Vector2d& q, const Eigen::Vector2d& f, Eigen::Vector2d& tau) const;
  /// True if `x` is reachable within the joint limits with the distal links at least
  /// min_transmission_rad away from alignment (workspace limits).
  bool in_workspace(const Eigen::Vector2d& x) const;
  /// A nominal centre of the workspace (where the dual-stage model of eq. 3.4 is linearised).
  Eigen::Vector2d workspace_centre() const;

 private:
  Eigen::Vector2d elbow(int i, double theta) const;
  Eigen::Vector2d base(int i) const;
  PantographParams params_;
};

}  // namespace mc::haptics
