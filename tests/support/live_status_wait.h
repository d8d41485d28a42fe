#pragma once
// Helpers of the live platform's tests: a telemetry channel's index by name, and a wait on the
// live status.

#include <chrono>
#include <stdexcept>
#include <string_view>
#include <thread>

#include "microcobot/live/live_platform.h"

namespace mc::test {

inline std::size_t telemetry_channel(const char* name) { return platform::telemetry_channel_index(name); }

// Polls `live`'s status every 10 ms until `done(status)` or `timeout_s` of wall time.
template <class Done>
bool wait_status(const live::LivePlatform& live, Done done, double timeout_s) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < until) {
    if (done(live.status())) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

}  // namespace mc::test
