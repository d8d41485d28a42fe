#pragma once
/// @file
/// The simulated parallel positioner's controller on a thread of its own. A SmarPod's or a PI
/// hexapod's controller runs the legs' servo on its own processor at its own rate; the host only
/// sends moves and reads poses. So does this one: it steps a motion::ParallelStage (the six legs'
/// stick-slip models and trackers) on its thread, paced by the wall clock at the stage's control
/// rate, and the platform's loop exchanges a few hundred bytes with it per tick instead of running
/// six legs' physics (docs/concepts/parallel-positioner.md, "The controller's thread").
///
///     host (the loop)                         controller thread (every wake_period_s)
///     start_move / follow / stop / ...  --->  ring of commands, applied in order
///     exchange(): view() <- newest status <---  the stage's ticks due by the wall clock, then
///                 heartbeat --------------->    a status: poses, flags, the legs' largest voltage
///
/// The host side (everything but the constructor and destructor) is called by one thread at a
/// time: the loop's, or, while the loop is stopped, the thread that runs it (the platform's
/// lifecycle transitions). It never allocates, locks or blocks. A command the full ring cannot
/// take returns false; a stop or an emergency stop is then kept in a flag the controller applies
/// after the ring. When the host stops exchanging for host_timeout_s, the controller stops any
/// move: every leg holds where it is measured (a controller that lost its host holds; it does
/// not cut the legs' power, which would let them slip).

#include <atomic>
#include <cstdint>
#include <optional>
#include <thread>

#include "microcobot/motion/parallel_stage.h"
#include "microcobot/runtime/latest_value.h"
#include "microcobot/runtime/spsc_ring.h"

namespace mc::devices {

struct ParallelPositionerControllerParams {
  /// How often the controller wakes to run the control periods due and publish a status [s]: the
  /// latency of a command and of the pose the host reads (a SmarPod reports its pose at ~1 kHz).
  double wake_period_s = 1e-3;
  /// A move stops (every leg holds) when the host has not exchanged for this long [s].
  double host_timeout_s = 0.05;
  /// At most this many control periods run in one wake; a controller that fell further behind
  /// (its thread starved) drops the rest of its backlog and counts a late wake.
  int max_periods_per_wake = 200;
  /// Commands that fit between two wakes (a followed target every loop tick: 10 a millisecond).
  int command_capacity = 512;

  template <class V>
  void visit(V& v) {
    v("wake_period_s", wake_period_s);
    v("host_timeout_s", host_timeout_s);
    v("max_periods_per_wake", max_periods_per_wake);
    v("command_capacity", command_capacity);
  }
  void validate() const;
};

/// What the host reads of the controller, as of its last wake.
struct ParallelPositionerStatus {
  motion::PlatformTransform measured;   ///< FK of the legs' sensors, {H}
  motion::PlatformTransform reference;  ///< the pose the legs are told to be at
  motion::PlatformTransform truth;      ///< the simulation's truth: FK of the true sliders
  double max_leg_voltage_V = 0.0;
  std::uint64_t periods = 0;     ///< control periods run since the start
  std::uint64_t late_wakes = 0;  ///< wakes that dropped a backlog
  std::uint64_t refused = 0;     ///< commands the stage refused when they arrived
  std::uint64_t applied = 0;     ///< the sequence number of the last command applied
  bool moving = false;
  bool following = false;
  bool follow_blocked = false;
  bool at_rest = false;
  bool halted = false;
  bool fault = false;
  bool host_lost = false;  ///< a move was stopped because the host fell silent
};

class ParallelPositionerController {
 public:
  using Status = ParallelPositionerStatus;

  /// Starts the thread; `stage` must outlive the controller and is the thread's alone from here
  /// on. Throws mc::InvalidParams.
  ParallelPositionerController(motion::ParallelStage& stage,
                               const ParallelPositionerControllerParams& params);
  /// Stops and joins the thread; the stage is the caller's again.
  ~ParallelPositionerController();
  ParallelPositionerController(const ParallelPositionerController&) = delete;
  ParallelPositionerController& operator=(const ParallelPositionerController&) = delete;

  /// Queues motion::ParallelStage's command of the same name; false when the ring is full.
  bool start_move(const motion::PoseTrajectory& checked) noexcept;
  bool follow(const motion::PlatformTransform& target, const motion::PoseMoveLimits& limits) noexcept;
  /// Queued; never lost (kept in a flag when the ring is full).
  void stop() noexcept;
  void emergency_stop() noexcept;
  /// Queues a rearm; a rearm the stage refuses (its fault latched) leaves Status::fault set.
  bool rearm() noexcept;
  /// Queues an open-loop stepping of one leg (arguments checked by the caller).
  bool step_leg(int leg, motion::LegPositioner positioner, int steps, double frequency_Hz) noexcept;

  /// The host's beat: view() becomes the controller's newest status.
  void exchange() noexcept;
  const Status& view() const noexcept { return view_; }
  /// The stage's flags as the host must see them: a move or a followed target sent and not yet
  /// applied is already moving (a script that waits for the end of a move it just started must
  /// not see the stage still at rest from before it).
  bool moving() const noexcept { return view_.moving || view_.applied < motion_sent_; }
  bool following() const noexcept { return view_.following || view_.applied < follow_sent_; }
  bool at_rest() const noexcept { return view_.at_rest && view_.applied >= sent_; }

 private:
  enum class Kind : std::uint8_t { kStartMove, kFollow, kStop, kEmergencyStop, kRearm, kStepLeg };
  struct Command {
    Kind kind = Kind::kStop;
    std::uint64_t seq = 0;
    std::optional<motion::PoseTrajectory> trajectory;
    motion::PlatformTransform target;
    motion::PoseMoveLimits limits;
    int leg = 0, steps = 0;
    motion::LegPositioner positioner = motion::LegPositioner::kRadial;
    double frequency_Hz = 0.0;
  };

  bool push(Command& c) noexcept;
  void run() noexcept;
  void apply(const Command& c, Status& s) noexcept;
  void publish(Status& s) noexcept;

  motion::ParallelStage& stage_;
  ParallelPositionerControllerParams p_;
  runtime::SpscRing<Command> commands_;
  runtime::LatestValue<Status> status_;
  Command scratch_;  ///< the host's command under construction (its storage made once)
  Status view_;
  std::uint64_t sent_ = 0;         ///< the last command's sequence number
  std::uint64_t motion_sent_ = 0;  ///< the last start_move's or follow's
  std::uint64_t follow_sent_ = 0;  ///< the last follow's
  std::atomic<std::uint64_t> beats_{0};
  std::atomic<bool> pending_stop_{false}, pending_emergency_stop_{false};
  std::atomic<bool> quit_{false};
  bool rearm_refused_ = false;  ///< the controller thread's: the last rearm was refused
  std::thread thread_;
};

}  // namespace mc::devices
