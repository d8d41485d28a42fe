// The assembly task's looks (assembly_task.h, "Looks"): what each sighting changes in what the
// task knows of its part, its bore and its insertion (what was seen is task_looks.h's).
#include <cmath>

#include "microcobot/cell/assembly_task.h"

namespace mc::cell {

void AssemblyTask::see(const Sighting& sighting) noexcept {
  if (status() != Status::kAwaitingLook) return;
  const Look look = looks_.awaited();
  looks_.took(look);
  switch (look) {
    case Look::kSlot:
      if (sighting.found && sighting.part_m.allFinite() && std::isfinite(sighting.yaw_rad)) {
        goal_.part_m = sighting.part_m.head<2>();
        goal_.part_yaw_rad = sighting.yaw_rad;
      }
      break;
    case Look::kBore:
      if (sighting.found && sighting.part_m.head<2>().allFinite()) goal_.target_m = sighting.part_m.head<2>();
      break;
    case Look::kHeld:
      if (sighting.found && sighting.part_m.allFinite()) {
        // Along the fingers' y from the tool point (the stage held still while the camera looked).
        search_.centre_on_held(
            (sighting.part_m.head<2>() - last_tip_.head<2>()).dot(search_.along_fingers()));
      }
      break;
    case Look::kAlign:
      // Nothing seen: the descent aims as without a camera, the search round the bore as seen.
      search_.shift_aim(looks_.saw_align(sighting, p_.align_max_looks));
      break;
    case Look::kPlaced:
      looks_.saw_placed(sighting);
      break;
    case Look::kNone:
      break;
  }
  // Back to the step as its level has it (an assisted approach looks at the slot first).
  supervisor_.after_look(step_);
}

AssemblyTask::Look AssemblyTask::look_before_moving() const noexcept {
  const bool insertion_start = search_.tries() == 0 && search_.phase() == InsertionSearch::Phase::kDescend &&
                               status() == Status::kRunning;
  return looks_.before_moving(step_, goal_.flat_seat, insertion_start);
}

}  // namespace mc::cell
