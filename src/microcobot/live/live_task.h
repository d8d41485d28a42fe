#pragma once
/// @file
/// The automatic insertion run live, supervised from the console
/// (`microcobot serve --cell`): the live platform's loop ticks a cell::AssemblyTask on the
/// slave's sensors and hands its console input to the coupling, so that the platform's limits
/// (grip, contact, floor: teleop/safety_limits.h) apply to it as to the operator. The
/// operator's controls (start, pause, resume, confirm, take over, hand back, step done, skip)
/// reach the loop as console actions through a single-producer ring; the task's state leaves it
/// through atomics for the status channel.
///
/// Rules, the platform's (not the page's):
///  - the task drives only while supervised: a console client holds control, its commands are
///    fresh (the heartbeat) and no device is faulted; otherwise it pauses. A gap in the heartbeat
///    of the client in control (a busy browser) pauses it only while it lasts, up to
///    `heartbeat_gap_s`; a longer gap, a released control (a closed page) or an e-stop latches
///    the pause: the operator resumes;
///  - paused, awaiting a confirmation or ended, it sends no deadman: the coupling's target stops
///    at the tick that applies the action and the stage holds;
///  - an ended task (succeeded or failed) leaves every axis holding (Platform::hold()) and the
///    console in control again;
///  - taken over (or a manual step), the console drives from where the coupling's target is (the
///    console's moves integrate from it: no step), and two of its inputs are re-taken before they
///    count, so that nothing the page held before the hand-over moves the stage: the deadman
///    must be seen released once, and the gripper slider must come within `gripper_pickup_m` of
///    the opening the gripper holds, or cross it (a "soft take-over", as a MIDI fader's pick-up);
///  - a started task outranks the vendor-protocol clients until it ends;
///  - with the cell's camera (`camera.enabled`), the task holds while a look is awaited; the looker thread
///    (live_looker.h) takes the request (look_request()), renders and measures off the loop, and
///    hands the sighting back through a ring (deliver()); a sighting for an older request (a look
///    abandoned by a take-over, a rebuilt scene) is dropped.
/// The loop's part never allocates, locks or throws (the task object is allocation-free).

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "microcobot/cell/assembly_task.h"
#include "microcobot/cell/cell_camera.h"
#include "microcobot/platform/platform.h"
#include "microcobot/runtime/spsc_ring.h"
#include "microcobot/teleop/teleoperation.h"

namespace mc::live {

/// The operator's controls of the live task (`/console/action` task_*).
enum class TaskAction : std::uint8_t {
  kStart,  ///< start the task (once per scene: Restart scene for another cycle)
  kPause,  ///< hold; resume goes on from there
  kResume,
  kConfirm,   ///< the go for a step whose autonomy is confirm
  kTakeOver,  ///< the console drives; the task waits
  kHandBack,  ///< the task again: the current step from where the stage is
  kStepDone,  ///< the task again: the next step (the operator did this one)
  kSkip,      ///< the next step, from where the stage is
};

/// One part of the batch the console works through (`serve --cell`, Next part): its microworld
/// (a grid load's neighbours among it) and the task's goal on it.
struct LivePart {
  int index = 0;  ///< in its batch
  microworld::PickPlaceParams world;
  cell::AssemblyGoal goal;
};

struct LiveTaskParams {
  cell::AssemblyGoal goal;
  /// The batch's parts in order (empty: the one `goal`, on the platform's world). The task starts
  /// on parts[part] (whose goal `goal` must then be); the console's Next part takes the next one.
  std::vector<LivePart> parts;
  int part = 0;
  cell::AssemblyTaskParams task;
  /// Indexed by cell::AssemblyTask::Step (a task file's `steps`, cell/task_file.h).
  std::array<cell::AssemblyTask::Autonomy, cell::AssemblyTask::kStepCount> autonomy = all_auto();
  /// The console's gripper command counts again once within this of the held opening.
  double gripper_pickup_m = 5e-6;
  /// A heartbeat gap of the client in control up to this long (after the commands went stale)
  /// pauses the task while it lasts; longer, the pause latches.
  double heartbeat_gap_s = 1.0;
  /// The cell's camera (`enabled`: it looks for the task; cell_camera.h, `serve --cell
  /// --cell-camera`): the live platform's LiveLooker answers the looks.
  cell::CellCameraParams camera;
  /// Throws mc::InvalidParams (the task's parameters and goal).
  void validate() const;
  static std::array<cell::AssemblyTask::Autonomy, cell::AssemblyTask::kStepCount> all_auto() {
    std::array<cell::AssemblyTask::Autonomy, cell::AssemblyTask::kStepCount> a{};
    a.fill(cell::AssemblyTask::Autonomy::kAuto);
    return a;
  }
};

/// The task as the loop last published it.
struct LiveTaskStatus {
  bool started = false;
  bool ended = false;  ///< succeeded or failed; the console has control again
  cell::AssemblyTask::Step step = cell::AssemblyTask::Step::kApproach;
  cell::AssemblyTask::Status status = cell::AssemblyTask::Status::kRunning;
  int search_tries = 0;
  double elapsed_s = 0.0;        ///< live time since it started (to its end)
  std::string failure;           ///< why it failed
  bool supervisor_lost = false;  ///< paused by the platform, latched: control, heartbeat or a fault lost
  bool heartbeat_gap = false;    ///< paused by the platform while the console's commands are stale
  int inserted = -1;  ///< at its end, the simulation's truth: 1 the pin is in its bore, 0 not, -1 unknown
  int looks = 0;      ///< the camera's sightings the task took
  int looks_found = 0;
  /// The look the task awaits (kNone: none).
  cell::AssemblyTask::Look look = cell::AssemblyTask::Look::kNone;
  int part = -1;  ///< the batch's part it works on (LivePart::index; -1: no batch)
  int parts = 0;  ///< the parts the console can go through (LiveTaskParams::parts)
  std::array<cell::AssemblyTask::Autonomy, cell::AssemblyTask::kStepCount> autonomy{};
  /// "idle" before the start, else the task's status name.
  std::string status_name() const;
};

class LiveTask {
 public:
  /// Validates; the task is built, not started. Throws mc::Error.
  explicit LiveTask(LiveTaskParams params);
  ~LiveTask();

  /// A fresh task, not started; pending actions dropped. The loop's thread only, between loop
  /// runs (scene (re)builds): it allocates.
  void reset();
  /// Works on the batch's part `i` (LiveTaskParams::parts) from the next reset(): the same thread
  /// and time as reset(). Throws mc::InvalidInput when there is no such part.
  void set_part(int i);
  /// The part worked on, an index into LiveTaskParams::parts (0 without a batch). Any thread.
  int part() const noexcept { return part_.load(std::memory_order_relaxed); }
  const LiveTaskParams& params() const noexcept { return params_; }
  /// One producer thread (the server's). Wait-free; false when the ring is full.
  bool push(TaskAction a) noexcept { return actions_.push(a); }

  /// The look the task awaits (kNone: none) and its request number. Any thread.
  struct LookRequest {
    std::uint64_t seq = 0;
    cell::AssemblyTask::Look look = cell::AssemblyTask::Look::kNone;
  };
  LookRequest look_request() const noexcept;
  /// The bore the task aims at now (world x, y): its drawing, or where the camera saw it. Any thread.
  Eigen::Vector2d target_m() const noexcept {
    return {target_x_m_.load(std::memory_order_relaxed), target_y_m_.load(std::memory_order_relaxed)};
  }
  /// The sighting for request `seq` (one producer thread: the looker's). Wait-free; false when the
  /// ring is full.
  bool deliver(std::uint64_t seq, const cell::AssemblyTask::Sighting& s) noexcept {
    return sightings_.push({seq, s});
  }

  /// The operator tick's part (loop thread): applies the pending actions, pauses an unsupervised
  /// task, ticks it on the sensors and, while it drives or holds, replaces the console's input
  /// `in` with its own; while the console drives (before the start, taken over, ended) applies
  /// the re-take rules to `in`. `home_m`: the stage's home (world frame); `in_control`: a console
  /// client holds control and no device is faulted; `fresh`: its commands are fresh.
  void tick(platform::Platform& p, const Eigen::Vector3d& home_m, double dt_s, bool in_control, bool fresh,
            teleop::ConsoleInput& in) noexcept;
  /// Started and not ended (loop thread).
  bool in_progress() const noexcept { return started_ && !ended_; }

  /// Any thread.
  LiveTaskStatus status() const;

 private:
  void apply(TaskAction a) noexcept;
  void console_takes_the_stage() noexcept;

  LiveTaskParams params_;
  std::unique_ptr<cell::AssemblyTask> task_;
  runtime::SpscRing<TaskAction> actions_{64};
  struct Delivery {
    std::uint64_t seq = 0;
    cell::AssemblyTask::Sighting sighting;
  };
  runtime::SpscRing<Delivery> sightings_{8};
  bool look_pending_ = false;  // loop thread: a look requested and not answered
  int looks_ = 0, looks_found_ = 0;
  std::uint64_t look_seq_ = 0;  // loop thread: the current request's number
  // Published: look_seq_ << kLookBits | the look awaited (AssemblyTask::Look's values fit the bits).
  static constexpr unsigned kLookBits = 3;
  static_assert(static_cast<unsigned>(cell::AssemblyTask::Look::kAlign) < (1u << kLookBits));
  std::atomic<std::uint64_t> look_word_{0};
  // The bore the task aims at (its drawing, or where the camera saw it): the looker's placed look.
  std::atomic<double> target_x_m_{0.0}, target_y_m_{0.0};
  std::atomic<int> looks_pub_{0}, looks_found_pub_{0};
  // Loop thread only.
  bool started_ = false, ended_ = false, operator_had_stage_ = false;
  teleop::FixtureSet fixtures_;  // the task's shared control in force on the coupling
  bool rearm_deadman_ = false, pickup_gripper_ = false;
  bool gap_paused_ = false;  // paused for a heartbeat gap: resumes by itself when it ends soon
  double gap_s_ = 0.0;
  double pickup_side_ = 0.0;  // the sign of the console's gripper command less the held opening
  double elapsed_s_ = 0.0;
  // Published by the loop.
  std::atomic<bool> started_pub_{false}, ended_pub_{false}, supervisor_lost_{false}, gap_pub_{false};
  std::atomic<int> step_{0}, status_{0}, tries_{0}, inserted_{-1};
  std::atomic<double> elapsed_pub_{0.0};
  std::atomic<const char*> failure_{""};
  std::atomic<int> part_{0};
};

}  // namespace mc::live
