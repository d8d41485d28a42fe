#include "microcobot/live/live_task.h"

#include <cmath>

#include "microcobot/cell/task_io.h"
#include "microcobot/core/error.h"

namespace mc::live {

using cell::AssemblyTask;
using Status = AssemblyTask::Status;

void LiveTaskParams::validate() const {
  task.validate();
  AssemblyTask check(task, goal);  // the goal's checks are the task's constructor's
  require(std::isfinite(gripper_pickup_m) && gripper_pickup_m > 0.0 && gripper_pickup_m < 100e-6,
          "gripper_pickup_m", "must be within (0, 100 um)", gripper_pickup_m);
  require(std::isfinite(heartbeat_gap_s) && heartbeat_gap_s >= 0.0 && heartbeat_gap_s <= 10.0,
          "heartbeat_gap_s", "must be within [0, 10] s", heartbeat_gap_s);
  try {
    camera.validate();
  } catch (const InvalidParams& e) {
    throw e.nested_in("camera");
  }
  if (!parts.empty()) {
    require(part >= 0 && part < static_cast<int>(parts.size()), "part",
            "must be one of the batch's parts (0 to " + std::to_string(parts.size() - 1) + ")",
            static_cast<double>(part));
    for (const LivePart& p : parts) {
      p.world.validate();
      AssemblyTask each(task, p.goal);
    }
  }
}

std::string LiveTaskStatus::status_name() const {
  return started ? std::string(AssemblyTask::name(status)) : std::string("idle");
}

LiveTask::LiveTask(LiveTaskParams params) : params_(std::move(params)) {
  params_.validate();
  if (!params_.parts.empty()) set_part(params_.part);
  reset();
}

void LiveTask::set_part(int i) {
  if (i < 0 || i >= static_cast<int>(params_.parts.size()))
    throw InvalidInput("part " + std::to_string(i) + ": the batch served has " +
                       std::to_string(params_.parts.size()) + " parts");
  params_.part = i;
  params_.goal = params_.parts[static_cast<std::size_t>(i)].goal;
  part_.store(i, std::memory_order_relaxed);
}

LiveTask::~LiveTask() = default;

void LiveTask::reset() {
  task_ = std::make_unique<AssemblyTask>(params_.task, params_.goal);
  task_->set_looks(params_.camera.enabled, params_.camera.servo);
  for (int i = 0; i + 1 < AssemblyTask::kStepCount; ++i)
    task_->set_autonomy(static_cast<AssemblyTask::Step>(i), params_.autonomy[static_cast<std::size_t>(i)]);
  TaskAction dropped;
  while (actions_.pop(dropped)) {
  }
  Delivery stale;
  while (sightings_.pop(stale)) {
  }
  look_pending_ = false;
  looks_ = looks_found_ = 0;
  ++look_seq_;  // a sighting still on its way for the old scene is dropped
  look_word_.store(look_seq_ << kLookBits);
  target_x_m_.store(params_.goal.target_m.x());
  target_y_m_.store(params_.goal.target_m.y());
  looks_pub_.store(0);
  looks_found_pub_.store(0);
  started_ = ended_ = operator_had_stage_ = false;
  rearm_deadman_ = pickup_gripper_ = gap_paused_ = false;
  gap_s_ = 0.0;
  elapsed_s_ = 0.0;
  started_pub_.store(false);
  ended_pub_.store(false);
  supervisor_lost_.store(false);
  gap_pub_.store(false);
  step_.store(static_cast<int>(task_->step()));
  status_.store(static_cast<int>(task_->status()));
  tries_.store(0);
  inserted_.store(-1);
  elapsed_pub_.store(0.0);
  failure_.store("");
}

void LiveTask::apply(TaskAction a) noexcept {
  AssemblyTask& task = *task_;
  if (a == TaskAction::kStart) {
    started_ = true;  // once: a started or ended task ignores it
    return;
  }
  if (!in_progress()) return;
  gap_paused_ = false;  // the operator decides from here (a pause keeps a heartbeat gap's pause)
  switch (a) {
    case TaskAction::kStart:
      break;
    case TaskAction::kPause:
      task.pause();
      break;
    case TaskAction::kResume:
      task.resume();
      supervisor_lost_.store(false, std::memory_order_relaxed);
      break;
    case TaskAction::kConfirm:
      task.confirm();
      break;
    case TaskAction::kTakeOver:
      task.take_over();
      break;
    case TaskAction::kHandBack:
      task.hand_back(false);
      break;
    case TaskAction::kStepDone:
      task.hand_back(true);
      break;
    case TaskAction::kSkip:
      task.skip();
      break;
  }
}

void LiveTask::console_takes_the_stage() noexcept {
  rearm_deadman_ = true;
  pickup_gripper_ = true;
  pickup_side_ = 0.0;
}

void LiveTask::tick(platform::Platform& p, const Eigen::Vector3d& home_m, double dt_s, bool in_control,
                    bool fresh, teleop::ConsoleInput& in) noexcept {
  TaskAction a;
  while (actions_.pop(a)) apply(a);
  if (in_progress()) {
    AssemblyTask& task = *task_;
    auto latch = [&] {  // stays paused: the operator resumes once back in control
      gap_paused_ = false;
      supervisor_lost_.store(true, std::memory_order_relaxed);
    };
    if (task.status() == Status::kRunning && !(in_control && fresh)) {
      task.pause();
      if (in_control) {
        gap_paused_ = true;  // the controlling client's heartbeat is late: perhaps only a while
        gap_s_ = 0.0;
      } else {
        latch();
      }
    }
    if (gap_paused_) {
      gap_s_ += dt_s;
      if (!in_control || gap_s_ > params_.heartbeat_gap_s) {
        latch();
      } else if (fresh) {
        task.resume();
        gap_paused_ = false;
      }
    }
    // The camera's answer to the look awaited (an older request's is dropped).
    Delivery d;
    while (sightings_.pop(d)) {
      if (look_pending_ && d.seq == look_seq_ && task.look_wanted() != AssemblyTask::Look::kNone) {
        task.see(d.sighting);
        look_pending_ = false;
        ++looks_;
        looks_found_ += d.sighting.found ? 1 : 0;
      }
    }
    const teleop::ConsoleInput& out = task.tick(cell::read_task_sensors(p, home_m), dt_s);
    if (task.look_wanted() == AssemblyTask::Look::kNone) {
      look_pending_ = false;  // answered, or abandoned (taken over, skipped)
    } else if (!look_pending_) {
      look_pending_ = true;
      ++look_seq_;
    }
    elapsed_s_ += dt_s;
    const bool operator_drives = task.operator_drives();
    // An assisted step's shared control on the coupling (installed on a change only: a set
    // installed again would slew its level from 0 again).
    if (!(task.fixtures() == fixtures_)) {
      fixtures_ = task.fixtures();
      p.set_fixtures(fixtures_);
    }
    if (operator_drives && !operator_had_stage_) console_takes_the_stage();
    operator_had_stage_ = operator_drives;
    if (!operator_drives) in = out;  // the task drives, or holds (no deadman)
    if (task.finished()) {
      if (!(fixtures_ == teleop::FixtureSet{})) p.set_fixtures(fixtures_ = {});
      p.hold();  // the sequence ends with every axis holding ...
      ended_ = true;
      console_takes_the_stage();  // ... and the console in control again
      const auto* gripper = p.simulated_gripper();
      inserted_.store(gripper == nullptr                                  ? -1
                      : gripper->world().inserted(gripper->world_state()) ? 1
                                                                          : 0,
                      std::memory_order_relaxed);
    }
  }
  if (!in_progress() || operator_had_stage_) {
    // The console drives: what it held before the hand-over is re-taken before it counts.
    if (rearm_deadman_) {
      if (!in.deadman) rearm_deadman_ = false;
      in.deadman = false;
    }
    if (pickup_gripper_ && in.has_gripper) {
      // Picked up within the tolerance, or when the command crosses the held opening.
      const double d = in.gripper_opening_m - p.teleop().gripper_opening_m;
      if (std::abs(d) <= params_.gripper_pickup_m || d * pickup_side_ < 0.0)
        pickup_gripper_ = false;
      else
        pickup_side_ = d > 0.0 ? 1.0 : -1.0;
    }
    if (pickup_gripper_) in.has_gripper = false;
  }
  const AssemblyTask& task = *task_;
  started_pub_.store(started_, std::memory_order_relaxed);
  step_.store(static_cast<int>(task.step()), std::memory_order_relaxed);
  status_.store(static_cast<int>(task.status()), std::memory_order_relaxed);
  tries_.store(task.search_tries(), std::memory_order_relaxed);
  elapsed_pub_.store(elapsed_s_, std::memory_order_relaxed);
  failure_.store(task.failure().data(), std::memory_order_relaxed);
  gap_pub_.store(gap_paused_, std::memory_order_relaxed);
  looks_pub_.store(looks_, std::memory_order_relaxed);
  looks_found_pub_.store(looks_found_, std::memory_order_relaxed);
  target_x_m_.store(task.goal().target_m.x(), std::memory_order_relaxed);
  target_y_m_.store(task.goal().target_m.y(), std::memory_order_relaxed);
  look_word_.store(
      look_seq_ << kLookBits | (look_pending_ ? static_cast<std::uint64_t>(task.look_wanted()) : 0u),
      std::memory_order_relaxed);
  ended_pub_.store(ended_, std::memory_order_release);  // last: the rest is read after it
}

LiveTask::LookRequest LiveTask::look_request() const noexcept {
  const std::uint64_t w = look_word_.load(std::memory_order_relaxed);
  LookRequest r;
  r.seq = w >> kLookBits;
  r.look = static_cast<AssemblyTask::Look>(w & ((1u << kLookBits) - 1u));
  return r;
}

LiveTaskStatus LiveTask::status() const {
  LiveTaskStatus s;
  s.ended = ended_pub_.load(std::memory_order_acquire);
  s.started = started_pub_.load(std::memory_order_relaxed);
  s.step = static_cast<AssemblyTask::Step>(step_.load(std::memory_order_relaxed));
  s.status = static_cast<Status>(status_.load(std::memory_order_relaxed));
  s.search_tries = tries_.load(std::memory_order_relaxed);
  s.elapsed_s = elapsed_pub_.load(std::memory_order_relaxed);
  s.failure = failure_.load(std::memory_order_relaxed);
  s.supervisor_lost = supervisor_lost_.load(std::memory_order_relaxed);
  s.heartbeat_gap = gap_pub_.load(std::memory_order_relaxed);
  s.inserted = inserted_.load(std::memory_order_relaxed);
  s.looks = looks_pub_.load(std::memory_order_relaxed);
  s.looks_found = looks_found_pub_.load(std::memory_order_relaxed);
  s.look = look_request().look;
  s.autonomy = params_.autonomy;
  if (!params_.parts.empty()) {  // the parts never change: only the index is the loop's
    s.part = params_.parts[static_cast<std::size_t>(part_.load(std::memory_order_relaxed))].index;
    s.parts = static_cast<int>(params_.parts.size());
  }
  return s;
}

}  // namespace mc::live
