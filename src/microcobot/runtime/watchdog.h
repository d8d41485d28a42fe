#pragma once
/// @file
/// Declares commands stale when they have not been refreshed for more than a set number of
/// ticks: the teleoperation coupling then puts the slave on hold and the haptic force to
/// zero. Real-time safe.

#include <cstdint>

namespace mc::runtime {

class Watchdog {
 public:
  /// Stale after more than `timeout_ticks` ticks without feed().
  explicit Watchdog(std::uint32_t timeout_ticks) : timeout_(timeout_ticks) {}

  /// A fresh command arrived.
  void feed() noexcept { since_feed_ = 0; }
  /// One tick passed; returns true while the commands are fresh.
  bool tick() noexcept {
    if (since_feed_ <= timeout_) ++since_feed_;
    return fresh();
  }
  bool fresh() const noexcept { return since_feed_ <= timeout_; }
  std::uint32_t ticks_since_feed() const { return since_feed_; }

 private:
  std::uint32_t timeout_;
  std::uint32_t since_feed_ = 0;
};

}  // namespace mc::runtime
