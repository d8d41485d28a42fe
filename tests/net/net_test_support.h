#pragma once
/// @file
/// Helpers of the net tests: a DDS domain id of this test process (parallel ctest runs are
/// separate processes, so they never share a domain) and waiting for a condition.

#include <unistd.h>

#include <chrono>
#include <thread>

#include "microcobot/net/cyclone_config.h"

namespace mc::net::test {

/// 1..kMaxDomainId from the pid (0 is ROS 2's default domain: left to real use).
inline int test_domain_id() { return 1 + static_cast<int>(::getpid() % kMaxDomainId); }

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

}  // namespace mc::net::test
