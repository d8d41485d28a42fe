#pragma once
/// @file
/// Helpers of the net tests: a DDS domain id of this test process (parallel ctest runs are
/// separate processes, so they never share a domain), waiting for a condition, and a peer that
/// publishes its role's state topics.

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>

#include "microcobot/net/cyclone_config.h"
#include "microcobot/net/link.h"

namespace mc::net::test {

/// 1..kMaxPortableDomainId from the pid (0 is ROS 2's default domain: left to real use; above
/// kMaxPortableDomainId another process' socket may hold the domain's port).
inline int test_domain_id() { return 1 + static_cast<int>(::getpid() % kMaxPortableDomainId); }

/// Polls `done` every millisecond for up to `timeout_s`; true when it became true.
template <class F>
bool wait_until(F done, double timeout_s = 10.0) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!done()) {
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

/// Publishes every periodic topic of `link`'s role at about 1 kHz on its own thread while `on`.
class StatePublisher {
 public:
  explicit StatePublisher(Link& link) : link_(link), thread_([this] { run(); }) {}
  ~StatePublisher() {
    quit_ = true;
    thread_.join();
  }
  std::atomic<bool> on{true};

 private:
  void run() {
    for (std::int64_t k = 1; !quit_; ++k) {
      if (on) {
        for (const TopicSpec& spec : topic_table()) {
          if (spec.publisher != link_.role() || spec.rate_Hz <= 0) continue;
          NetSample s;
          s.channel = spec.channel;
          s.stamp_ns = k * 1'000'000;
          // Valid everywhere: devices active (lifecycle 2) on /diagnostics, 0 m / 0 N elsewhere.
          if (spec.channel == Channel::kSlaveDiagnostics) s.xyz = {2, 2, 2}, s.scalar = 2;
          link_.send(s);
        }
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  Link& link_;
  std::atomic<bool> quit_{false};
  std::thread thread_;
};

}  // namespace mc::net::test
