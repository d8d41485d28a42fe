#pragma once
/// @file
/// The other parts of a scene (several parts in one scene, `layout: grid`): the pins still in
/// the tray and the parts already placed on the plate stand on the substrate as rigid square blocks
/// the gripper must not strike. Each is a footprint (a square turned about the vertical) up to its
/// top; the fingers (two rectangles finger_thickness_m x finger_width_m at their opening) and a held
/// part below a neighbour's top that overlap its footprint meet it with the substrate's stiffness
/// along the axis of least overlap (the separating-axis test of two oriented rectangles: Gottschalk,
/// Lin and Manocha, "OBBTree", SIGGRAPH 1996, in the plane).

#include <array>

#include <Eigen/Dense>

namespace mc::microworld {

/// A part standing on the substrate (world frame).
struct NeighbourPart {
  Eigen::Vector2d xy_m = Eigen::Vector2d::Zero();  ///< its centre
  double yaw_rad = 0.0;
  double side_m = 0.0;   ///< its square's side
  double top_z_m = 0.0;  ///< the height of its top above the substrate
};

/// A rectangle in the plane: centre, half sides along its own axes, turned by yaw.
struct Footprint {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  Eigen::Vector2d half = Eigen::Vector2d::Zero();
  double yaw_rad = 0.0;
};

/// How far `b` overlaps `a` (0: apart) and the unit direction that takes `b` out of `a` by that
/// much (separating axes: both rectangles' sides). Never allocates.
double overlap(const Footprint& a, const Footprint& b, Eigen::Vector2d& out_of_a) noexcept;

}  // namespace mc::microworld
