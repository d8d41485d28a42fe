#pragma once
/// @file
/// The slave micro-gripper in its microworld: a PiezoGripper carried by the XYZ stage over a
/// substrate with a micro-part (microworld::PickPlaceWorld, thesis §1.1.1 surface forces).
/// The gripper's position is where the stage carries it (SlaveAxis::carried_position_m: the
/// simulated axes' truth, a driver's sensor) plus the mount offset `home_m` (where the finger
/// tips are when every axis is at 0). The safe state keeps the last opening command: a gripper
/// that let go of the part on a fault would drop it. With a rotary axis (set_rotary) the fingers
/// turn with it about the vertical through their tips. Its align drives (the 4-DOF PiezoGripper's
/// vertical benders) raise or lower each tip in the microworld; the safe state holds them where
/// they are (a tip let down on a fault could strike the substrate). On a parallel positioner
/// (set_carrier: the thesis's assembly) the substrate, the part on it and its hole ride on the
/// positioner's top plate: the microworld is stepped in the seat's frame (carried_seat.h), and
/// what this class reports (the contact force, the part's place, the fingers' bend) is in the world's.

#include <array>

#include "microcobot/devices/carried_seat.h"
#include "microcobot/devices/device.h"
#include "microcobot/microworld/pick_place_world.h"
#include "microcobot/motion/rotary_axis.h"

namespace mc::devices {

class SimulatedParallelPositioner;

class SimulatedGripper final : public Gripper {
 public:
  /// `world` and the axes must outlive the gripper.
  SimulatedGripper(std::string name, const microworld::PickPlaceWorld& world,
                   std::array<const SlaveAxis*, 3> axes, const Vec3& home_m);

  void command_opening_m(double opening) noexcept override;
  double opening_m() const override { return out_.opening_m; }
  double grip_force_N() const override { return out_.grip_force_N; }
  /// The bender's free opening: the simulated drive is ideal (first order and slew limited, no
  /// hysteresis), so its open-loop model is exact (docs/errata.md).
  double free_opening_m() const override { return state_.gripper.free_opening_m; }
  Vec3 contact_force_N() const override {
    const Eigen::Vector3d f = seat_.vector_to_world(out_.force_on_gripper_N);
    return {f.x(), f.y(), f.z()};
  }
  /// The burst shakes the fingers in the microworld while on (an inactive gripper ignores it).
  void command_shake(bool on) noexcept override { shake_ = active() && on; }
  bool can_shake() const override { return true; }
  bool has_align_drives() const override { return true; }
  /// Clamped to the drives' range; ignored when inactive or not finite.
  void command_align_V(const std::array<double, 2>& drives_V) noexcept override;
  std::array<double, 2> align_V() const override { return align_V_; }
  double align_limit_V() const override { return world_.params().gripper.align.max_voltage_V; }
  /// The tips' contact forces in the microworld (a force sensor at each tip).
  std::array<double, 2> tip_contact_N() const override { return out_.tips.contact_N; }
  /// The tips' vertical misalignment off the substrate: finger 1's height minus finger 0's [m].
  double tip_misalignment_m() const noexcept { return out_.tip_misalignment_m; }
  void update(double dt_s) noexcept override;
  /// The safe state keeps the opening but stops the burst.
  void enter_safe_state() noexcept override { shake_ = false; }

  /// The rotary axis that turns the fingers (`axis` must outlive the gripper); call before
  /// configure().
  void set_rotary(const SlaveAxis* axis, const motion::RotaryAxisParams& params) {
    rotary_ = axis;
    rotary_params_ = params;
  }
  /// The parallel positioner whose top plate carries the substrate (`positioner` must outlive the
  /// gripper; its true pose is read at every update); call before configure().
  void set_carrier(const SimulatedParallelPositioner* positioner) noexcept { carrier_ = positioner; }
  /// The seat's pose at the last update: the carrier's composed with the seat's tilt on it
  /// (identity without a carrier and without a tilt).
  const CarriedSeat& seat() const noexcept { return seat_; }
  /// The part's centre and orientation about the vertical, in the world's frame.
  Eigen::Vector3d part_position_m() const noexcept { return seat_.to_world(state_.part_m); }
  double part_yaw_rad() const noexcept { return state_.part_yaw_rad + seat_.yaw_rad(); }
  /// Where the finger tips are (world frame), and the fingers' yaw (0 without a rotary axis).
  Eigen::Vector3d tip_position_m() const;
  double yaw_rad() const noexcept {
    return rotary_ != nullptr ? rotary_params_.angle_rad(rotary_->carried_position_m()) : 0.0;
  }
  /// The fingers' common-mode bend under a lateral force (world x, y): the tips are seen there,
  /// away from tip_position_m() (microworld/pick_place_world.h).
  Eigen::Vector2d finger_deflection_m() const {
    const Eigen::Vector3d bend(state_.finger_deflection_m.x(), state_.finger_deflection_m.y(), 0.0);
    return seat_.vector_to_world(bend).head<2>();
  }
  /// The microworld's state, in the seat's frame (the world's without a carrier).
  const microworld::PickPlaceState& world_state() const { return state_; }
  const microworld::PickPlaceOutput& world_output() const { return out_; }
  const microworld::PickPlaceWorld& world() const { return world_; }

 protected:
  void on_configure() override;

 private:
  /// One step of the microworld in the seat's frame, from the carrier's pose now.
  void step_world(double dt_s) noexcept;

  const microworld::PickPlaceWorld& world_;
  const SimulatedParallelPositioner* carrier_ = nullptr;
  CarriedSeat seat_;
  std::array<const SlaveAxis*, 3> axes_;
  const SlaveAxis* rotary_ = nullptr;
  motion::RotaryAxisParams rotary_params_;
  Eigen::Vector3d home_m_;
  microworld::PickPlaceState state_;
  microworld::PickPlaceOutput out_;
  double command_m_;
  motion::PlatformTransform mount_;  ///< the seat on its carrier (world.seat_tilt_x_rad, _y_rad)
  bool shake_ = false;
  std::array<double, 2> align_V_{};
};

}  // namespace mc::devices
