// The assembly task's looks (assembly_task.h, "Looks"): which look a step needs before it moves,
// and what each sighting changes in what the task knows of its part and bore.
#include <cmath>

#include "microcobot/cell/assembly_task.h"

namespace mc::cell {

void AssemblyTask::see(const Sighting& sighting) noexcept {
  if (status_ != Status::kAwaitingLook) return;
  switch (look_) {
    case Look::kSlot:
      slot_seen_ = true;
      if (sighting.found && sighting.part_m.allFinite() && std::isfinite(sighting.yaw_rad)) {
        goal_.part_m = sighting.part_m.head<2>();
        goal_.part_yaw_rad = sighting.yaw_rad;
      }
      break;
    case Look::kBore:
      bore_seen_ = true;
      if (sighting.found && sighting.part_m.head<2>().allFinite()) goal_.target_m = sighting.part_m.head<2>();
      break;
    case Look::kHeld:
      held_seen_ = true;
      if (sighting.found && sighting.part_m.allFinite()) {
        // Along the fingers' y from the tool point (the stage held still while the camera looked).
        const Eigen::Vector2d ey(-std::sin(search_yaw_), std::cos(search_yaw_));
        held_offset_ = (sighting.part_m.head<2>() - last_tip_.head<2>()).dot(ey);
        search_base_ = offset_y_ = -held_offset_;
      }
      break;
    case Look::kPlaced:
      placed_seen_ = true;
      placed_ = sighting;
      break;
    case Look::kNone:
      break;
  }
  // Back to the step as its level has it (an assisted approach looks at the slot first).
  status_ = autonomy_[index(step_)] == Autonomy::kAssisted && assistable(step_) ? Status::kAssisted
                                                                                : Status::kRunning;
}

AssemblyTask::Look AssemblyTask::look_before_moving() const noexcept {
  if (!looks_) return Look::kNone;
  if (step_ == Step::kApproach && !slot_seen_) return Look::kSlot;
  if (step_ == Step::kTransport && !bore_seen_ && !goal_.flat_seat) return Look::kBore;
  if (step_ == Step::kInsert && !held_seen_ && tries_ == 0 && insert_ == Insert::kDescend &&
      status_ == Status::kRunning)
    return Look::kHeld;
  return Look::kNone;
}

}  // namespace mc::cell
