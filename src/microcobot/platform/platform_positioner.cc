// The platform's parallel positioner (`positioner: parallel`; devices/parallel_positioner.h): the
// simulated one built from the configuration when no driver brings one (or the registered driver
// `parallel_positioner.driver` names, platform/driver_registry.h), its pose moves and followed
// poses under the deadman of the input that drives the coupling, its update on every tick. It
// carries the substrate (devices/carried_seat.h): a move that brings the seat onto the finger tips
// stops as the XYZ stage's target would (teleop/safety_limits.h: the floor, the contact limit).
#include <algorithm>
#include <memory>

#include "microcobot/devices/carried_seat.h"
#include "microcobot/devices/simulated_parallel_positioner.h"
#include "microcobot/platform/driver_registry.h"
#include "microcobot/platform/platform.h"

namespace mc::platform {

void Platform::build_positioner() {
  if (devices_.positioner || !config_.parallel_positioner_enabled()) return;
  if (!config_.parallel_positioner.simulated()) {
    devices_.positioner = make_positioner(config_);  // a driver's (parallel_positioner.driver)
    return;
  }
  // The legs are the project's stick-slip axes: the platform's model and step map.
  const auto& c = config_.parallel_positioner;
  auto p = std::make_unique<devices::SimulatedParallelPositioner>(
      "parallel_positioner", *model_, *map_, c, config_.loop.period_s(),
      c.controller_on_thread() ? std::optional(c.controller_thread) : std::nullopt);
  sim_.positioner = p.get();
  if (sim_.gripper != nullptr) sim_.gripper->set_carrier(p.get());  // the part rides on it
  devices_.positioner = std::move(p);
}

bool Platform::start_pose_move(const motion::PoseTrajectory& checked) noexcept {
  // A move that would bring the seat within the tips' floor is refused before anything moves
  // (from where the tips stand now: nothing else moves them while the console moves the plate).
  return devices_.positioner != nullptr && pose_move_allowed() &&
         devices::lowest_tip_height_m(checked, tips_m(), coupling_.seat_on_plate) >=
             world_.params().min_tip_height_m &&
         devices_.positioner->start_move(checked);
}

Eigen::Vector3d Platform::tips_m() const noexcept {
  Eigen::Vector3d tips = home_m_;
  for (std::size_t i = 0; i < 3; ++i) tips[static_cast<Eigen::Index>(i)] += devices_.axes[i]->position_m();
  return tips;
}

bool Platform::follow_pose(const motion::PlatformTransform& target,
                           const motion::PoseMoveLimits& limits) noexcept {
  return devices_.positioner != nullptr && pose_move_allowed() && devices_.positioner->follow(target, limits);
}

void Platform::positioner_task(double dt_s) noexcept {
  devices::ParallelPositioner* p = devices_.positioner.get();
  if (p == nullptr) return;
  const bool master = coupling_.master_on && master_pose_task();
  // A move or a followed target runs only under the rule it started with: the deadman released,
  // the input stale or outranked, or a fault, and every leg holds where it is measured.
  const bool closing = seat_closes_on_tips();
  if ((p->moving() || p->following()) && (!(pose_move_allowed() || master) || closing)) {
    p->stop();
    ++coupling_.stops;
  }
  p->update(dt_s);
}

void Platform::switch_master_slave(bool to_positioner) noexcept {
  coupling_.master_on = to_positioner;
  coupling_.master_driving = false;
  const Eigen::Vector3d stage(devices_.axes[0]->position_m(), devices_.axes[1]->position_m(),
                              devices_.axes[2]->position_m());
  if (to_positioner) {
    coupling_.stage_hold_m = teleop_->output().slave_target_m;  // where the gripper was asked to be
    teleop_->hold_at(devices_.positioner->measured_pose().d);
  } else {
    devices_.positioner->stop();
    teleop_->hold_at(stage);
  }
}

bool Platform::master_pose_task() noexcept {
  // The handle's x, y, z through the coupling (its scale, clutch, deadman, freshness and limits)
  // place the plate; the console's dial, under the console's deadman, turns it about the vertical.
  const teleop::TeleoperationOutput& out = teleop_->output();
  const auto& limits = config_.parallel_positioner.move;
  const bool dial = !faulted_ && console_.fresh && console_.deadman && console_.theta_rate_rad_s != 0.0;
  if (faulted_ || !(out.engaged || dial)) {
    // The plate stops short of the coupling's target (it follows at its own speed): the coupling
    // takes up again from where the plate holds, as the Cartesian robot's from where it is.
    if (coupling_.master_driving) teleop_->hold_at(devices_.positioner->measured_pose().d);
    coupling_.master_driving = false;
    return false;
  }
  if (!coupling_.master_driving) coupling_.master_pose = devices_.positioner->reference_pose();  // no jump
  coupling_.master_driving = true;
  if (out.engaged) coupling_.master_pose.d = out.slave_target_m;
  if (dial) {
    const double rate = std::clamp(console_.theta_rate_rad_s, -limits.max_angular_speed_rad_s,
                                   limits.max_angular_speed_rad_s);
    coupling_.master_pose.R =
        motion::exp_so3(Eigen::Vector3d(0.0, 0.0, rate * config_.loop.period_s())) * coupling_.master_pose.R;
  }
  // The coupling's target stays under the ceiling (Teleoperation::set_height_ceiling); the dial
  // may have turned the plate since, so the pose asked for is held to it too.
  coupling_.master_pose.d.z() =
      std::min(coupling_.master_pose.d.z(), plate_ceiling_m(coupling_.master_pose.R));
  return devices_.positioner->follow(coupling_.master_pose, limits);
}

double Platform::plate_ceiling_m(const Eigen::Matrix3d& R) const noexcept {
  const Eigen::Vector3d tips = tips_m();
  const motion::PlatformTransform& mount = coupling_.seat_on_plate;
  Eigen::Vector3d under =
      devices::CarriedSeat::on_plate(devices_.positioner->measured_pose(), mount).to_seat(tips);
  under.z() = 0.0;  // on the seat's surface
  return tips.z() - world_.params().min_tip_height_m - (R * (mount.R * under + mount.d)).z();
}

double Platform::stage_floor_m() const noexcept {
  const auto seat =
      devices::CarriedSeat::on_plate(devices_.positioner->measured_pose(), coupling_.seat_on_plate);
  Eigen::Vector3d under = seat.to_seat(tips_m());
  under.z() = 0.0;  // on the seat's surface
  return seat.to_world(under).z() + world_.params().min_tip_height_m - home_m_.z();
}

bool Platform::seat_closes_on_tips() noexcept {
  // From what a real platform knows: the legs' reference and measured poses, the Cartesian
  // robot's axes and the gripper's contact force. The reference, free of the sensors' noise,
  // says which way the seat went this tick.
  const Eigen::Vector3d tips = tips_m();
  const motion::PlatformTransform& mount = coupling_.seat_on_plate;
  const auto last = devices::CarriedSeat::on_plate(coupling_.seat_reference, mount);
  const auto now = devices::CarriedSeat::on_plate(devices_.positioner->reference_pose(), mount);
  coupling_.seat_reference = devices_.positioner->reference_pose();
  const Eigen::Vector3d under = last.to_seat(tips);  // the seat's point under the tips
  const Eigen::Vector3d moved = now.to_world(under) - last.to_world(under);
  const double clearance =
      devices::CarriedSeat::on_plate(devices_.positioner->measured_pose(), mount).to_seat(tips).z();
  const devices::Vec3 f = devices_.gripper->contact_force_N();
  const Eigen::Vector3d force(f.x, f.y, f.z);
  const bool under_floor = clearance < world_.params().min_tip_height_m && moved.z() > 0.0;
  const bool pressing = force.norm() > world_.params().contact_force_limit_N && force.dot(moved) > 0.0;
  return under_floor || pressing;
}

}  // namespace mc::platform
