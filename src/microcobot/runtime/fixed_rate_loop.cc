#include "microcobot/runtime/fixed_rate_loop.h"

#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "microcobot/core/error.h"
#include "microcobot/runtime/cpu_affinity.h"

namespace mc::runtime {

namespace {
double seconds(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
double now_s() { return seconds(CLOCK_MONOTONIC); }
// A system call: the vDSO does not serve the thread CPU clock.
double thread_cpu_s() { return seconds(CLOCK_THREAD_CPUTIME_ID); }
}  // namespace

FixedRateLoop::FixedRateLoop(double base_rate_Hz) : rate_(base_rate_Hz) {
  require(std::isfinite(base_rate_Hz) && base_rate_Hz > 0 && base_rate_Hz <= 1e6, "loop.base_rate_Hz",
          "must be in (0, 1e6]", base_rate_Hz);
  period_ = 1.0 / rate_;
}

void FixedRateLoop::add_task(std::string name, int divisor, TaskFn fn) {
  require(divisor >= 1, "loop.task." + name + ".divisor", "must be >= 1", divisor);
  require(static_cast<bool>(fn), "loop.task." + name, "needs a function");
  tasks_.push_back(Task{std::move(name), divisor, std::move(fn)});
}

void FixedRateLoop::pin_to_core(int cpu) {
  require(cpu == -1 || core_allowed(cpu), "loop.cpu",
          "must be -1 (not pinned) or a core this process may use (" + allowed_cores() + ")", cpu);
  cpu_ = cpu;
}

void FixedRateLoop::sample_ticks_every(int divisor) {
  require(divisor >= 1, "loop.sample_ticks_every", "must be >= 1", divisor);
  sample_every_ = static_cast<std::uint64_t>(divisor);
}

std::vector<std::pair<std::string, int>> FixedRateLoop::tasks() const {
  std::vector<std::pair<std::string, int>> out;
  for (const auto& t : tasks_) out.emplace_back(t.name, t.divisor);
  return out;
}

void FixedRateLoop::tick_once() noexcept {
  const double t = time_s();
  for (auto& task : tasks_) {
    if (tick_ % static_cast<std::uint64_t>(task.divisor) == 0) {
      task.fn(TickInfo{tick_, t, period_ * task.divisor});
    }
  }
  ++tick_;
}

double FixedRateLoop::timed_tick() noexcept {
  const bool sampled = tick_ % sample_every_ == 0;
  // The CPU clock's reads bracket the wall clock's, so that they do not lengthen the wall time.
  const double cpu_start = sampled ? thread_cpu_s() : 0.0;
  const double start = now_s();
  tick_once();
  const double cost = now_s() - start;
  last_tick_s_ = cost;
  if (sampled) {
    sampled_tick_cpu_s_ = thread_cpu_s() - cpu_start;
    sampled_tick_s_ = cost;
  }
  tick_stats_.add(cost);
  return cost;
}

void FixedRateLoop::run_for(std::uint64_t ticks) {
  stop_.store(false);
  thread_id_.store(std::this_thread::get_id());
  for (std::uint64_t i = 0; i < ticks && !stop_requested(); ++i) {
    if (timed_tick() > period_) ++overruns_;
  }
}

bool FixedRateLoop::run_realtime(std::uint64_t ticks) {
  stop_.store(false);
  thread_id_.store(std::this_thread::get_id());
  bool fifo = false;
  std::thread worker([&] {
    sched_param param{};
    param.sched_priority = sched_get_priority_max(SCHED_FIFO) - 10;
    fifo = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
    // Before the first tick: the pinning walks /proc and makes system calls.
    if (cpu_ >= 0 && pin_calling_thread(cpu_)) move_other_threads_off(cpu_);
    thread_id_.store(std::this_thread::get_id());
    timespec next{};
    clock_gettime(CLOCK_MONOTONIC, &next);
    const auto period_ns = static_cast<long>(std::llround(period_ * 1e9));
    for (std::uint64_t i = 0; i < ticks && !stop_requested(); ++i) {
      next.tv_nsec += period_ns;
      while (next.tv_nsec >= 1000000000L) {
        next.tv_nsec -= 1000000000L;
        ++next.tv_sec;
      }
      clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
      const double start = now_s();
      const double deadline = static_cast<double>(next.tv_sec) + 1e-9 * static_cast<double>(next.tv_nsec);
      const double late = start - deadline;
      jitter_stats_.add(late);
      if (late > kResyncPeriods * period_) {
        // Far behind (the process was stopped, the machine overloaded): skip the missed ticks
        // rather than run them back to back, which would starve the machine and make up nothing.
        clock_gettime(CLOCK_MONOTONIC, &next);
        ++resyncs_;
      }
      if (timed_tick() > period_ || late > period_) ++overruns_;
    }
  });
  worker.join();
  if (cpu_ >= 0) give_core_back(cpu_);
  return fifo;
}

}  // namespace mc::runtime
