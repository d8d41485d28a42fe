#pragma once
/// @file
/// The substrate carried by the parallel positioner: the thesis's assembly (§2.3, Fig. 2.4) puts
/// the part on the 6-DOF robot and the gripper on the Cartesian one. The substrate is the
/// positioner's top plate, and the world frame is that plate's frame at home (the microworld's
/// origin at the plate's centre, its z = 0 the plate's surface): the plate's pose T = (R, d)
/// relative to home (motion::PlatformTransform, the positioner's true pose) carries every point of
/// the substrate, the part resting on it and its hole with it, p_world = R p_seat + d. The
/// microworld (microworld/pick_place_world.h) is stepped in the seat's frame: the gripper's point
/// is taken there, its yaw less the seat's, and the seat's tilt against the gripper's vertical
/// decides how deep a held part goes into its hole.
///
/// A seat need not sit flat on its plate (a fixture's tilt, microworld::PickPlaceParams::
/// seat_tilt_x_rad): the seat's pose is then the plate's composed with the seat's own on the plate,
/// T = T_plate M (on_plate()). The simulation knows M; a platform knows only what it measured of
/// it (platform::Platform::set_seat_on_plate, the cell's touch probe: cell/seat_levelling.h).

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "microcobot/motion/pose.h"
#include "microcobot/motion/pose_trajectory.h"

namespace mc::devices {

struct CarriedSeat {
  motion::PlatformTransform T;  ///< the seat's pose in the world (identity: at home)

  /// The seat mounted by `mount` (its pose in the plate's frame) on a plate at `plate`.
  static CarriedSeat on_plate(const motion::PlatformTransform& plate,
                              const motion::PlatformTransform& mount) noexcept {
    return CarriedSeat{motion::PlatformTransform{plate.R * mount.R, plate.R * mount.d + plate.d}};
  }

  Eigen::Vector3d to_seat(const Eigen::Vector3d& world_m) const noexcept {
    return T.R.transpose() * (world_m - T.d);
  }
  Eigen::Vector3d to_world(const Eigen::Vector3d& seat_m) const noexcept { return T.R * seat_m + T.d; }
  /// A vector (a force, a displacement) from the seat's axes to the world's.
  Eigen::Vector3d vector_to_world(const Eigen::Vector3d& v) const noexcept { return T.R * v; }
  /// The seat's heading about the vertical: the angle of its x axis projected on the world's plane.
  double yaw_rad() const noexcept { return std::atan2(T.R(1, 0), T.R(0, 0)); }
  /// The angle between the seat's normal and the world's vertical (the gripper's axis).
  double tilt_rad() const noexcept { return std::acos(std::clamp(T.R(2, 2), -1.0, 1.0)); }
  /// How high `world_m` stands over the seat's surface, along its normal.
  double height_over_m(const Eigen::Vector3d& world_m) const noexcept { return to_seat(world_m).z(); }
};

/// A seat tilted on its plate by Ry(tilt_y_rad) Rx(tilt_x_rad) about the plate's origin.
inline motion::PlatformTransform tilted_mount(double tilt_x_rad, double tilt_y_rad) noexcept {
  motion::PlatformTransform m;
  m.R = Eigen::AngleAxisd(tilt_y_rad, Eigen::Vector3d::UnitY()).toRotationMatrix() *
        Eigen::AngleAxisd(tilt_x_rad, Eigen::Vector3d::UnitX()).toRotationMatrix();
  return m;
}

/// The lowest the finger tips at `tips_m` (world) stand over the seat while the plate runs `path`
/// (its poses T(s)): sampled every 10 um of the tool point's travel and every 1 mrad of its turn
/// (at least 16 samples, both ends included), as motion::check_move() samples a path. The height is
/// smooth in s, so between two samples it dips below them by at most h^2 max|f''| / 8, under a
/// nanometre at these spacings. Never allocates.
/// `mount` is the seat's pose on the plate (CarriedSeat::on_plate).
inline double lowest_tip_height_m(const motion::PoseTrajectory& path, const Eigen::Vector3d& tips_m,
                                  const motion::PlatformTransform& mount = {}) noexcept {
  const double by_length = path.length_m() / 10e-6, by_angle = path.angle_rad() / 1e-3;
  const int n = static_cast<int>(std::min(1e6, std::max({16.0, std::ceil(by_length), std::ceil(by_angle)})));
  double lowest = CarriedSeat::on_plate(path.start(), mount).height_over_m(tips_m);
  for (int i = 1; i <= n; ++i)
    lowest = std::min(
        lowest, CarriedSeat::on_plate(path.at(static_cast<double>(i) / n), mount).height_over_m(tips_m));
  return lowest;
}

}  // namespace mc::devices
