#pragma once
/// @file
/// A deterministic fixed-rate executor, the heart of the platform's real-time path.
///
/// One base rate (10 kHz for the haptic path); each task runs every `divisor` base ticks
/// (divisor 10 gives the 1 kHz slave control), in the order the tasks were added. Tasks are
/// added while configuring (that allocates); running never allocates, locks or does I/O on
/// the loop path. Two ways to run:
///  - run_for(n): simulation, back to back as fast as possible; time advances by the period.
///  - run_realtime(n): paced to the wall clock with absolute deadlines (clock_nanosleep) in a
///    dedicated thread, SCHED_FIFO when the process may use it, best effort otherwise.
/// Both measure each tick's compute time on the wall clock (a tick preempted by another thread
/// lasts longer) and, on the sampled ticks, also on the loop thread's CPU clock (what the tick
/// itself cost, preemption excluded); real time also measures wake-up lateness (jitter).
/// An overrun is a tick whose compute time exceeded the period, or, in real time, a tick that
/// started a full period late. A real-time loop that falls more than kResyncPeriods behind
/// (a stopped process, an overloaded machine) skips the missed ticks instead of bursting.

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "microcobot/runtime/timing_stats.h"

namespace mc::runtime {

/// What a task is told at each of its ticks.
struct TickInfo {
  std::uint64_t index;  ///< base tick index
  double t_s;           ///< simulated time of this tick
  double dt_s;          ///< the task's own period
};

/// A task's update: must be real-time safe (noexcept, no allocation, lock or I/O).
using TaskFn = std::function<void(const TickInfo&)>;

class FixedRateLoop {
 public:
  explicit FixedRateLoop(double base_rate_Hz);

  /// Adds `fn` to run every `divisor` base ticks. Configuration phase only.
  void add_task(std::string name, int divisor, TaskFn fn);

  /// Runs `ticks` base ticks back to back (simulation).
  void run_for(std::uint64_t ticks);
  /// Runs `ticks` base ticks paced to the wall clock in a real-time thread; blocks until
  /// done or request_stop(). Returns whether SCHED_FIFO was granted.
  bool run_realtime(std::uint64_t ticks);
  /// Stops a run at the end of the current tick. Safe from any thread or from a task.
  void request_stop() noexcept { stop_.store(true, std::memory_order_relaxed); }
  bool stop_requested() const { return stop_.load(std::memory_order_relaxed); }

  double base_rate_Hz() const { return rate_; }
  double period_s() const { return period_; }
  std::uint64_t ticks() const { return tick_; }
  double time_s() const { return static_cast<double>(tick_) * period_; }
  const TimingStats& tick_stats() const { return tick_stats_; }
  const TimingStats& jitter_stats() const { return jitter_stats_; }
  std::uint64_t overruns() const { return overruns_; }
  /// Compute time of the last finished tick [s] (read by a task: the previous tick's).
  double last_tick_s() const { return last_tick_s_; }
  /// The sampled ticks are those whose index is a multiple of `divisor` (1: every tick; a
  /// telemetry task's divisor: the ticks where every task runs, the heaviest). Configuration
  /// phase only. Their CPU time is read off the thread's CPU clock, which costs a system call
  /// (~1.3 us on the 2-core VM of docs/benchmarks.md: reading it at every 10 kHz tick would
  /// cost the loop more than a tenth of its tick).
  void sample_ticks_every(int divisor);
  /// Real time only: the loop's thread runs on core `cpu` and, while it runs, the process's
  /// other non-real-time threads keep off that core (runtime/cpu_affinity.h); -1 (the default)
  /// leaves placement to the kernel. Configuration phase only.
  void pin_to_core(int cpu);
  int pinned_core() const { return cpu_; }
  /// Compute time of the last finished sampled tick [s], on the wall clock.
  double sampled_tick_s() const { return sampled_tick_s_; }
  /// The same tick's CPU time on the loop thread's clock [s]: a preemption (another thread,
  /// another tenant of the machine) does not count; what other threads cost the tick itself
  /// (shared caches, memory bandwidth) does, and so does about one clock read.
  double sampled_tick_cpu_s() const { return sampled_tick_cpu_s_; }
  /// Ticks skipped to catch up with the wall clock (real time only), counted in resyncs.
  std::uint64_t resyncs() const { return resyncs_; }
  /// The thread that runs (or last ran) the ticks: how a test proves the loop path allocates
  /// nothing while other threads (a server) do.
  std::thread::id thread_id() const { return thread_id_.load(); }
  static constexpr double kResyncPeriods = 100.0;
  /// Task names and divisors, in execution order.
  std::vector<std::pair<std::string, int>> tasks() const;

 private:
  struct Task {
    std::string name;
    int divisor;
    TaskFn fn;
  };
  void tick_once() noexcept;
  /// One tick, timed: wall clock always, the thread's CPU clock on a sampled tick. Returns the
  /// wall-clock compute time.
  double timed_tick() noexcept;

  double rate_;
  double period_;
  std::vector<Task> tasks_;
  std::uint64_t tick_ = 0;
  std::uint64_t overruns_ = 0;
  std::uint64_t resyncs_ = 0;
  std::atomic<std::thread::id> thread_id_{};
  double last_tick_s_ = 0.0;
  std::uint64_t sample_every_ = 1;
  int cpu_ = -1;
  double sampled_tick_s_ = 0.0;
  double sampled_tick_cpu_s_ = 0.0;
  TimingStats tick_stats_;
  TimingStats jitter_stats_;
  std::atomic<bool> stop_{false};
};

}  // namespace mc::runtime
