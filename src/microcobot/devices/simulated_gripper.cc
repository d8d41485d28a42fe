#include "microcobot/devices/simulated_gripper.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"
#include "microcobot/devices/simulated_parallel_positioner.h"

namespace mc::devices {

SimulatedGripper::SimulatedGripper(std::string name, const microworld::PickPlaceWorld& world,
                                   std::array<const SlaveAxis*, 3> axes, const Vec3& home_m)
    : Gripper(std::move(name)),
      world_(world),
      axes_(axes),
      home_m_(home_m.x, home_m.y, home_m.z),
      state_(world.initial_state()),
      command_m_(world.params().gripper.max_opening_m),
      mount_(tilted_mount(world.params().seat_tilt_x_rad, world.params().seat_tilt_y_rad)) {
  for (const auto* a : axes_) require(a != nullptr, this->name() + ".axes", "must all be set");
  require(home_m_.allFinite(), this->name() + ".home_m", "must be finite");
}

void SimulatedGripper::on_configure() {
  state_ = world_.initial_state();
  command_m_ = world_.params().gripper.max_opening_m;
  shake_ = false;
  align_V_ = {};
  seat_ = CarriedSeat::on_plate(carrier_ != nullptr ? carrier_->true_pose() : motion::PlatformTransform{},
                                mount_);
  state_.last_gripper_m = seat_.to_seat(tip_position_m());
  state_.last_gripper_yaw_rad = yaw_rad() - seat_.yaw_rad();
  step_world(0.0);
}

void SimulatedGripper::step_world(double dt_s) noexcept {
  seat_ = CarriedSeat::on_plate(carrier_ != nullptr ? carrier_->true_pose() : motion::PlatformTransform{},
                                mount_);
  out_ = world_.step(state_, seat_.to_seat(tip_position_m()), command_m_, dt_s, yaw_rad() - seat_.yaw_rad(),
                     align_V_, seat_.tilt_rad());
}

Eigen::Vector3d SimulatedGripper::tip_position_m() const {
  return home_m_ + Eigen::Vector3d(axes_[0]->carried_position_m(), axes_[1]->carried_position_m(),
                                   axes_[2]->carried_position_m());
}

void SimulatedGripper::command_opening_m(double opening) noexcept {
  if (active() && std::isfinite(opening)) command_m_ = opening;
}

void SimulatedGripper::command_align_V(const std::array<double, 2>& drives_V) noexcept {
  if (!active() || !std::isfinite(drives_V[0]) || !std::isfinite(drives_V[1])) return;
  const double limit = align_limit_V();
  for (std::size_t k = 0; k < 2; ++k) align_V_[k] = std::clamp(drives_V[k], -limit, limit);
}

void SimulatedGripper::update(double dt_s) noexcept {
  state_.gripper.shaking = shake_;
  step_world(dt_s);
}

}  // namespace mc::devices
