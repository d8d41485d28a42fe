#include "microcobot/cell/task_looks.h"

namespace mc::cell {

void TaskLooks::new_insertion() noexcept {
  held_seen_ = false;
  aligned_ = align_move_ = false;
  align_looks_ = 0;
}

TaskLook TaskLooks::before_moving(TaskStep step, bool flat_seat, bool insertion_start) const noexcept {
  if (!on_) return TaskLook::kNone;
  if (step == TaskStep::kApproach && !slot_seen_) return TaskLook::kSlot;
  if (step == TaskStep::kTransport && !bore_seen_ && !flat_seat) return TaskLook::kBore;
  // The servo aligns a pin on its bore as seen from the bore's station; a flat seat shows nothing
  // to servo on (its place is its drawing's), so a flat part takes the held look.
  if (step == TaskStep::kInsert && insertion_start) {
    if (servo_ && !flat_seat) {
      if (!aligned_ && !align_move_) return TaskLook::kAlign;
    } else if (!held_seen_) {
      return TaskLook::kHeld;
    }
  }
  return TaskLook::kNone;
}

void TaskLooks::took(TaskLook look) noexcept {
  switch (look) {
    case TaskLook::kSlot:
      slot_seen_ = true;
      break;
    case TaskLook::kBore:
      bore_seen_ = true;
      break;
    case TaskLook::kHeld:
      held_seen_ = true;
      break;
    default:
      break;
  }
}

Eigen::Vector2d TaskLooks::saw_align(const TaskSighting& sighting, int max_looks) noexcept {
  // The look-and-move servo: the tool moves by minus the error seen (the stage's loop makes the
  // displacement), then looks again, until converged or out of looks. Nothing seen: the descent
  // aims as without a camera.
  ++align_looks_;
  Eigen::Vector2d correction = Eigen::Vector2d::Zero();
  if (sighting.found && sighting.error_m.allFinite()) {
    if (!sighting.converged) correction = -sighting.error_m;
    aligned_ = sighting.converged || align_looks_ >= max_looks;
  } else {
    aligned_ = true;
  }
  align_move_ = !aligned_;
  return correction;
}

}  // namespace mc::cell
