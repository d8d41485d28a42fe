#pragma once
/// @file
/// The simulated 6-DOF parallel positioner a hexapod twin (gcs2_hexapod_twin.h) drives: it owns a
/// motion::ParallelStage (six stick-slip legs with their trackers; docs/concepts/parallel-positioner.md)
/// and steps it on a loop thread of its own, since the live platform has no parallel positioner
/// device yet.
///
/// Threads. The loop (runtime::FixedRateLoop, 1 kHz, each period ParallelStage::tick() as often as
/// the trackers' rate asks: 10 at their 10 kHz) is the stage's only user. The protocol thread
/// plans and checks a move (motion's PoseTrajectory and check_move(), which may allocate and
/// throw) and hands the checked trajectory to the loop through a runtime::SpscRing; a stop goes
/// through an atomic sequence number, so that it overtakes the moves queued before it. The loop's
/// state leaves it as one runtime::LatestValue snapshot (poses, flags and the sequence numbers of
/// what it applied), consistent as a whole. The loop path never allocates, locks, throws or does
/// I/O (ParallelStage::start_move(), tick()).
///
/// Moves queue: one that arrives while another runs starts where that one ends (its goal, held
/// exactly), so the protocol thread plans it from there.

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <thread>

#include "microcobot/motion/parallel_stage.h"
#include "microcobot/runtime/fixed_rate_loop.h"
#include "microcobot/runtime/latest_value.h"
#include "microcobot/runtime/spsc_ring.h"

namespace mc::twins {

struct HexapodStageParams {
  motion::ParallelStageParams stage;  ///< the library's defaults (docs/parameters.md)
  /// The loop's rate: the platform's slave-control rate (docs/architecture.md, "Threads and rings").
  double loop_rate_Hz = 1000.0;
  /// Moves the ring holds between the protocol thread and the loop.
  std::size_t queue = 64;
  void validate() const;
};

/// What the loop publishes after each period.
struct HexapodView {
  motion::PlatformTransform measured;  ///< FK of the six sensors' readings, {H}
  motion::PlatformTransform
      reference;                   ///< the pose the legs are told to be at (held: the start of the next move)
  bool moving = false;             ///< a move runs (or is queued in the loop)
  bool at_rest = false;            ///< no move, every tracker powered up and in position
  bool fault = false;              ///< the stage stopped on a fault (every leg at 0 V)
  std::uint64_t started_seq = 0;   ///< the last move started (its seq)
  std::uint64_t rejected_seq = 0;  ///< the last move the stage refused to start
  std::uint64_t stop_seq = 0;      ///< the last stop applied
  double time_s = 0.0;             ///< the stage's simulated time
};

class HexapodStage {
 public:
  explicit HexapodStage(HexapodStageParams p = {});
  ~HexapodStage();
  HexapodStage(const HexapodStage&) = delete;
  HexapodStage& operator=(const HexapodStage&) = delete;

  /// Starts the loop thread (idempotent). Until then nothing moves and commands wait in the ring.
  void start();
  /// Stops the loop thread; the stage holds where it is. Idempotent.
  void stop_loop();
  bool running() const { return thread_.joinable(); }

  /// Protocol thread: queues a checked move (its seq must increase). False when the ring is full.
  bool push_move(const motion::PoseTrajectory& checked, std::uint64_t seq);
  /// Protocol thread: stops every move at once, queued ones included (`seq` larger than theirs).
  void push_stop(std::uint64_t seq) noexcept { stop_seq_.store(seq, std::memory_order_release); }
  /// The loop's newest snapshot (one reader: the protocol thread).
  HexapodView view() noexcept { return view_.read(); }

  /// Immutable after construction: safe from any thread.
  const motion::ParallelKinematics& kinematics() const noexcept { return stage_.kinematics(); }
  const motion::PoseMoveLimits& move_limits() const noexcept { return p_.stage.move; }
  const HexapodStageParams& params() const noexcept { return p_; }
  /// Loop ticks run (the loop thread's counter; for tests).
  std::uint64_t ticks() const noexcept { return ticks_.load(std::memory_order_relaxed); }
  /// The loop's thread id while it runs (a test counts its allocations).
  std::thread::id loop_thread() const { return loop_->thread_id(); }

 private:
  struct Command {
    std::optional<motion::PoseTrajectory> traj;
    std::uint64_t seq = 0;
  };
  void period() noexcept;

  HexapodStageParams p_;
  motion::ParallelStage stage_;
  int ticks_per_period_ = 1;
  runtime::SpscRing<Command> ring_;
  runtime::LatestValue<HexapodView> view_;
  std::atomic<std::uint64_t> stop_seq_{0};
  std::atomic<std::uint64_t> ticks_{0};
  std::atomic<bool> quit_{false};  ///< stop_loop() asked: the loop ends at its next period
  // Loop thread only.
  Command next_;
  bool has_next_ = false;
  std::uint64_t stop_applied_ = 0, started_ = 0, rejected_ = 0;
  std::unique_ptr<runtime::FixedRateLoop> loop_;
  std::thread thread_;
};

}  // namespace mc::twins
