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
    case Look::kAlign:
      // The look-and-move servo: the tool moves by minus the error seen (the stage's loop makes
      // the displacement), then looks again, until converged or out of looks. Nothing seen: the
      // descent aims as without a camera, the search round the bore as seen.
      ++align_looks_;
      if (sighting.found && sighting.error_m.allFinite()) {
        if (!sighting.converged) aim_ -= sighting.error_m;
        aligned_ = sighting.converged || align_looks_ >= p_.align_max_looks;
      } else {
        aligned_ = true;
      }
      align_move_ = !aligned_;
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
  // The servo aligns a pin on its bore as seen from the bore's station; a flat seat shows nothing
  // to servo on (its place is its drawing's), so a flat part takes the held look.
  if (step_ == Step::kInsert && tries_ == 0 && insert_ == Insert::kDescend && status_ == Status::kRunning) {
    if (servo_ && !goal_.flat_seat) {
      if (!aligned_ && !align_move_) return Look::kAlign;
    } else if (!held_seen_) {
      return Look::kHeld;
    }
  }
  return Look::kNone;
}

}  // namespace mc::cell
