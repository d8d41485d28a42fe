#include "microcobot/live/remote_source.h"

#include <chrono>

namespace mc::live {

SourceRequest RemoteSource::poll(const SourceTick& t) noexcept {
  // Timed on the steady clock: a vDSO read, no system call.
  const auto t0 = std::chrono::steady_clock::now();
  const RemoteRequest r = link_.poll(t.tick.t_s, latest_);
  cost_ = std::chrono::steady_clock::now() - t0;
  fresh_.store(r.fresh, std::memory_order_relaxed);
  return {Claim::kActive, r.estop, r.reset};
}

void RemoteSource::drive(const SourceTick&, teleop::ConsoleInput& in) noexcept {
  in = coupling_input(latest_, fresh_.load(std::memory_order_relaxed), max_theta_speed_rad_s_);
}

void RemoteSource::publish(const SourceTick& t) noexcept {
  const auto t0 = std::chrono::steady_clock::now();
  link_.publish(t.platform);
  cost_ += std::chrono::steady_clock::now() - t0;
  costs_.push(std::chrono::duration<double>(cost_).count());  // a full ring drops it
}

void RemoteSource::drain_costs(runtime::TimingStats& stats) noexcept {
  double cost_s = 0.0;
  while (costs_.pop(cost_s)) stats.add(cost_s);
}

}  // namespace mc::live
