#pragma once
/// @file
/// The master process of a distributed platform, seen from the slave (`serve --role slave`):
/// its link (remote_link.h) polled at every operator tick in place of the console. Always
/// active: the far operator is the only one who drives here (the local console observes and may
/// e-stop); its freshness and deadman are the link's. Its e-stop latches ours and its release
/// resets what it latched. Its work on the loop thread (the link's poll and publish) is timed.

#include <atomic>

#include "microcobot/live/command_source.h"
#include "microcobot/live/console_command.h"
#include "microcobot/live/remote_link.h"
#include "microcobot/runtime/spsc_ring.h"
#include "microcobot/runtime/timing_stats.h"

namespace mc::live {

class RemoteSource final : public CommandSource {
 public:
  /// `link`: not owned, outlives the source. `max_theta_speed_rad_s`: the rotary axis' goal speed.
  RemoteSource(RemoteLink& link, double max_theta_speed_rad_s)
      : link_(link), max_theta_speed_rad_s_(max_theta_speed_rad_s) {}

  /// The far end's commands are fresh (as of the last tick). Any thread.
  bool fresh() const noexcept { return fresh_.load(std::memory_order_relaxed); }
  /// Moves the link's cost to the loop measured since the last call into `stats`: the duration
  /// of its poll() and publish() in each operator tick. One consumer thread.
  void drain_costs(runtime::TimingStats& stats) noexcept;

  std::string_view name() const noexcept override { return "remote"; }
  SourceRequest poll(const SourceTick& t) noexcept override;
  void drive(const SourceTick& t, teleop::ConsoleInput& in) noexcept override;
  void publish(const SourceTick& t) noexcept override;
  void reset() noexcept override { latest_ = ConsoleCommand{}; }

 private:
  RemoteLink& link_;
  double max_theta_speed_rad_s_;
  ConsoleCommand latest_;  // loop thread: the far end's latest command
  std::chrono::steady_clock::duration cost_{};
  runtime::SpscRing<double> costs_{4096};  // loop -> status thread [s]
  std::atomic<bool> fresh_{false};
};

}  // namespace mc::live
