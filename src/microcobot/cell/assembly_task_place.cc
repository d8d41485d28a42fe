// The task's placing steps (assembly_task.h): the force-guarded insertion with its search
// (insertion_search.h), the release with the part's strategy (microworld/release.h), and the
// verify.
#include <algorithm>
#include <cmath>
#include <limits>

#include "microcobot/cell/assembly_task.h"

namespace mc::cell {

void AssemblyTask::insert_tick(const TaskSensors& s, double dt) noexcept {
  const Eigen::Vector2d xy = search_xy();
  const double floor_z =
      surface_z_ - goal_.hole_depth_m;  // tips when the pin's bottom is on the bore's floor
  switch (search_.phase()) {
    case InsertionSearch::Phase::kDescend: {
      if (looks_.align_move()) {  // the servo's correction, at the carrying height, before its next look
        if (move_to({xy.x(), xy.y(), carry_z_}, p_.insert_speed_m_s, s, dt)) looks_.align_moved();
        break;
      }
      // Aim below the floor: the descent ends on a contact, on the rim or on the floor. Slowly
      // only where a contact may come: the last 20 um to the surface and to the floor.
      const double z = s.tip_m.z(), near = 20e-6;
      const bool free = z > surface_z_ + near || (z < surface_z_ - near && z > floor_z + near);
      move_to({xy.x(), xy.y(), floor_z - near}, free ? p_.z_speed_m_s : p_.insert_speed_m_s, s, dt);
      if (s.contact_N.z() <= p_.contact_threshold_N) {
        if (settled_s_ > 0.0) fail("no contact below the bore's floor: the pin is not in the fingers");
        break;
      }
      const double contact_z = s.tip_m.z();
      search_.record_contact(contact_z);
      if (goal_.flat_seat || contact_z < surface_z_ - 0.5 * goal_.hole_depth_m) {
        enter(Step::kRelease);  // down in the bore, or on the flat seat
        break;
      }
      // On the rim: the next point of the search along the fingers' y.
      if (!search_.next_point(p_.search_step_factor * goal_.clearance_m, p_.search_range_m)) {
        fail("jammed: no fit within search_range_m");
        break;
      }
      search_.retreat_from(s.tip_m.head<2>(), std::min(contact_z + p_.search_retreat_m, carry_z_));
      settled_s_ = 0.0;
      break;
    }
    case InsertionSearch::Phase::kRetreat:
      // Straight up from where the descent stopped (or from where the operator handed back).
      if (!search_.retreat_known())
        search_.retreat_from(s.tip_m.head<2>(), std::min(s.tip_m.z() + p_.search_retreat_m, carry_z_));
      if (move_to({search_.retreat_xy_m().x(), search_.retreat_xy_m().y(), search_.retreat_z_m()},
                  p_.z_speed_m_s, s, dt)) {
        search_.set_phase(InsertionSearch::Phase::kShift);
        settled_s_ = 0.0;
      }
      break;
    case InsertionSearch::Phase::kShift:
      if (move_to({xy.x(), xy.y(), search_.retreat_z_m()}, p_.insert_speed_m_s, s, dt)) {
        search_.set_phase(InsertionSearch::Phase::kDescend);
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

void AssemblyTask::verify_tick(const TaskSensors& s, double dt) noexcept {
  // Still where the retract ended (settle_s), then one look.
  if (!move_to(s.tip_m, p_.z_speed_m_s, s, dt)) return;
  if (looks_.on() && !looks_.placed_seen()) {  // the camera's look, holding
    looks_.await(Look::kPlaced);
    supervisor_.await_look();
    out_.deadman = false;
    return;
  }
  if (looks_.on() && !looks_.placed().found) {
    fail("the camera does not see the pin down in its bore");
    return;
  }
  if (const Eigen::Vector3d part = looks_.on() ? looks_.placed().part_m : s.part_m; part.allFinite()) {
    const double inserted_z = 0.5 * goal_.part_height_m - goal_.hole_depth_m;
    // Off the axis along the bore's own sides.
    const Eigen::Vector2d d = part.head<2>() - goal_.target_m;
    const double c = std::cos(goal_.target_yaw_rad), sn = std::sin(goal_.target_yaw_rad);
    const double off_axis = std::max(std::abs(c * d.x() + sn * d.y()), std::abs(-sn * d.x() + c * d.y()));
    if (part.z() > inserted_z + p_.verify_tolerance_m) {
      fail(goal_.flat_seat ? "the part is not down on its seat (seen by the cell's vision)"
                           : "the pin is not down in its bore (seen by the cell's vision)");
      return;
    }
    // A flat seat's tolerance is told as its clearance; a pin is off its bore's axis.
    const double allowed = goal_.clearance_m + (goal_.flat_seat ? 0.0 : p_.verify_tolerance_m);
    if (off_axis > allowed) {
      fail(goal_.flat_seat ? "the part is off its seat (seen by the cell's vision)"
                           : "the pin is off its bore's axis (seen by the cell's vision)");
      return;
    }
  }
  enter(Step::kDone);
}

}  // namespace mc::cell
