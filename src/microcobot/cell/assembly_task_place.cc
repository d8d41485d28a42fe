// The task's placing steps (assembly_task.h): the force-guarded insertion with its search, and the
// release with the part's strategy (microworld/release.h).
#include <algorithm>
#include <cmath>
#include <limits>

#include "microcobot/cell/assembly_task.h"

namespace mc::cell {

void AssemblyTask::insert_tick(const TaskSensors& s, double dt) noexcept {
  const Eigen::Vector2d xy = search_xy();
  const double floor_z = grasp_z_ - goal_.hole_depth_m;  // tips when the pin's bottom is on the bore's floor
  switch (insert_) {
    case Insert::kDescend: {
      if (align_move_) {  // the servo's correction, at the carrying height, before its next look
        if (move_to({xy.x(), xy.y(), carry_z_}, p_.insert_speed_m_s, s, dt)) align_move_ = false;
        break;
      }
      // Aim below the floor: the descent ends on a contact, on the rim or on the floor. Slowly
      // only where a contact may come: the last 20 um to the surface and to the floor.
      const double z = s.tip_m.z(), near = 20e-6;
      const bool free = z > grasp_z_ + near || (z < grasp_z_ - near && z > floor_z + near);
      move_to({xy.x(), xy.y(), floor_z - near}, free ? p_.z_speed_m_s : p_.insert_speed_m_s, s, dt);
      if (s.contact_N.z() <= p_.contact_threshold_N) {
        if (settled_s_ > 0.0) fail("no contact below the bore's floor: the pin is not in the fingers");
        break;
      }
      contact_z_ = s.tip_m.z();
      if (goal_.flat_seat || contact_z_ < grasp_z_ - 0.5 * goal_.hole_depth_m) {
        enter(Step::kRelease);  // down in the bore, or on the flat seat
        break;
      }
      // On the rim: the next point of the search along the fingers' y (0, +s, -s, +2s, -2s, ...).
      ++tries_;
      const double step = p_.search_step_factor * goal_.clearance_m;
      const int k = (tries_ + 1) / 2;
      offset_y_ = search_base_ + (tries_ % 2 == 1 ? 1.0 : -1.0) * k * step;
      if (std::abs(offset_y_ - search_base_) > p_.search_range_m + 1e-12) {
        fail("jammed: no fit within search_range_m");
        break;
      }
      retreat_xy_ = s.tip_m.head<2>();
      retreat_z_ = std::min(contact_z_ + p_.search_retreat_m, carry_z_);
      insert_ = Insert::kRetreat;
      settled_s_ = 0.0;
      break;
    }
    case Insert::kRetreat:
      // Straight up from where the descent stopped (or from where the operator handed back).
      if (!std::isfinite(retreat_z_)) {
        retreat_xy_ = s.tip_m.head<2>();
        retreat_z_ = std::min(s.tip_m.z() + p_.search_retreat_m, carry_z_);
      }
      if (move_to({retreat_xy_.x(), retreat_xy_.y(), retreat_z_}, p_.z_speed_m_s, s, dt)) {
        insert_ = Insert::kShift;
        settled_s_ = 0.0;
      }
      break;
    case Insert::kShift:
      if (move_to({xy.x(), xy.y(), retreat_z_}, p_.insert_speed_m_s, s, dt)) {
        insert_ = Insert::kDescend;
        settled_s_ = 0.0;
      }
      break;
  }
}

void AssemblyTask::release_tick(const TaskSensors& s, double dt) noexcept {
  opening_command_ = goal_.open_m;
  out_.gripper_opening_m = opening_command_;
  move_to(s.tip_m, p_.z_speed_m_s, s, dt);  // stay
  switch (release_) {
    case Release::kOpen:
      settled_s_ = s.opening_m >= 0.9 * goal_.open_m ? settled_s_ : 0.0;
      if (settled_s_ < p_.settle_s) return;
      if (goal_.release == microworld::ReleaseStrategy::kOpen) {
        enter(Step::kRetract);
        return;
      }
      release_ = Release::kStrategy;
      release_s_ = 0.0;
      if (goal_.release == microworld::ReleaseStrategy::kRoll) {
        // The way that stays within the rotary axis' travel.
        const double up = s.yaw_rad + p_.roll_rad;
        turn_to(up <= goal_.yaw_max_rad ? up : s.yaw_rad - p_.roll_rad);
      }
      return;
    case Release::kStrategy:
      release_s_ += dt;
      if (goal_.release == microworld::ReleaseStrategy::kShake) {
        out_.gripper_shake = release_s_ < p_.shake_s;
        if (out_.gripper_shake) return;
      } else if (std::abs(s.yaw_rad - yaw_goal_) > p_.yaw_tolerance_rad) {
        return;  // still turning
      }
      enter(Step::kRetract);
      return;
  }
}

}  // namespace mc::cell
