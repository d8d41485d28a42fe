#pragma once
// A TwinStage whose state the test sets: what the twins read, and a log of what they asked.

#include <atomic>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "microcobot/twins/twin_stage.h"

namespace mc::twins::testing {

struct FakeStage : TwinStage {
  /// The rotary axis (theta) is there unless a test takes it away.
  explicit FakeStage(bool rotary = true) : axes_present(rotary ? 4 : 3) {}
  int axes_present;
  std::array<Axis, kMaxAxes> axes{};
  bool is_halted = false, console = false;
  ClientId owner = 0;
  std::vector<std::string> log;
  Goal last_goal{};
  double last_speed = 0.0, last_theta_speed = 0.0;

  int axis_count() const override { return axes_present; }
  Axis axis(int i) const override { return axes[static_cast<std::size_t>(i)]; }
  // Linear: +-5 mm at 1 mm/s; theta: the platform's +-62 deg (1.08 rad) at 0.16 rad/s.
  double min(int i) const override { return i == kTheta ? -1.08 : -5e-3; }
  double max(int i) const override { return i == kTheta ? 1.08 : 5e-3; }
  double max_speed(int i) const override { return i == kTheta ? 0.16 : 1e-3; }
  double max_voltage_V() const override { return 100.0; }
  bool halted() const override { return is_halted; }
  bool controls(ClientId c) const override { return owner == c && !console; }
  Refusal claim(ClientId c) {
    if (is_halted) return Refusal::kHalted;
    if (console || (owner != 0 && owner != c)) return Refusal::kOtherOperator;
    owner = c;
    return Refusal::kNone;
  }
  Refusal move_to(ClientId c, const Goal& goal, double speed, double theta_speed) override {
    const Refusal r = claim(c);
    if (r == Refusal::kNone) {
      last_goal = goal;
      last_speed = speed;
      last_theta_speed = theta_speed;
      log.push_back("move");
    }
    return r;
  }
  Refusal step(ClientId c, int i, double a, double f, int dir, std::int64_t n) override {
    const Refusal r = claim(c);
    if (r == Refusal::kNone) {
      log.push_back("step " + std::to_string(i) + " " + std::to_string(static_cast<int>(a)) + " " +
                    std::to_string(static_cast<int>(f)) + " " + std::to_string(dir) + " " +
                    std::to_string(n));
      axes[static_cast<std::size_t>(i)].stepping = true;
    }
    return r;
  }
  void stop(ClientId c) override {
    if (controls(c)) log.push_back("stop");
  }
  void release(ClientId c) override {
    if (owner == c) {
      owner = 0;
      log.push_back("release");
    }
  }
  /// Milliseconds the next heartbeat blocks the protocol thread: a server starved of the CPU.
  std::atomic<int> stall_next_heartbeat_ms{0};
  void heartbeat() override {
    if (const int ms = stall_next_heartbeat_ms.exchange(0))
      std::this_thread::sleep_for(std::chrono::milliseconds(ms));
  }
};

}  // namespace mc::twins::testing
