#pragma once
/// @file
/// The camera's looks an assembly task takes (assembly_task.h, "Looks"): which look a step needs
/// before it moves, which were taken, and the visual servo's count of align looks. What a look
/// changes in the task's goal and its insertion is the task's (AssemblyTask::see); this object
/// keeps what has been seen. Never allocates; noexcept.

#include <Eigen/Dense>

#include "microcobot/cell/task_steps.h"

namespace mc::cell {

class TaskLooks {
 public:
  /// The cell has a camera (`on`); the insertion aligned by the visual servo (`servo`: align
  /// looks) or by one held look.
  void enable(bool on, bool servo) noexcept {
    on_ = on;
    servo_ = servo;
  }
  bool on() const noexcept { return on_; }

  /// A fresh insertion: its held look, or its align looks, are to be taken again.
  void new_insertion() noexcept;
  /// The look `step` needs before it moves (kNone: none, or no camera). `insertion_start`: the
  /// insertion's first descent has neither jammed nor begun (the robot running it).
  TaskLook before_moving(TaskStep step, bool flat_seat, bool insertion_start) const noexcept;

  /// The look the task now waits for (or the last one).
  void await(TaskLook look) noexcept { look_ = look; }
  TaskLook awaited() const noexcept { return look_; }
  /// The awaited slot, bore or held look was taken (found or not).
  void took(TaskLook look) noexcept;
  /// An align look: counted; the servo is done once it converged, after `max_looks` looks, or when
  /// it saw nothing. Returns the aim's correction: minus the error seen, while not converged.
  Eigen::Vector2d saw_align(const TaskSighting& sighting, int max_looks) noexcept;
  /// Verify's look.
  void saw_placed(const TaskSighting& sighting) noexcept {
    placed_seen_ = true;
    placed_ = sighting;
  }

  /// The tool moves to the servo's corrected aim before the next align look.
  bool align_move() const noexcept { return align_move_; }
  void align_moved() noexcept { align_move_ = false; }
  int align_looks() const noexcept { return align_looks_; }
  bool placed_seen() const noexcept { return placed_seen_; }
  const TaskSighting& placed() const noexcept { return placed_; }

 private:
  bool on_ = false, servo_ = false;
  TaskLook look_ = TaskLook::kNone;
  bool slot_seen_ = false, bore_seen_ = false, held_seen_ = false;
  bool aligned_ = false;     // the servo done: converged, out of looks, or nothing seen
  bool align_move_ = false;  // the tool moving to the corrected aim before the next look
  int align_looks_ = 0;      // align looks taken for this insertion
  TaskSighting placed_;
  bool placed_seen_ = false;
};

}  // namespace mc::cell
