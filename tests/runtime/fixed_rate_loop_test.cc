#include "microcobot/runtime/fixed_rate_loop.h"

#include <gtest/gtest.h>
#include <sched.h>
#include <time.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "microcobot/core/error.h"
#include "microcobot/runtime/cpu_affinity.h"
#include "support/counting_allocator.h"

namespace mc::runtime {
namespace {

TEST(FixedRateLoop, TasksRunAtTheirDivisorInOrderWithTheirPeriod) {
  FixedRateLoop loop(10000.0);
  std::vector<char> order;
  order.reserve(64);
  int haptic = 0, slave = 0;
  double slave_dt = 0, last_t = -1;
  loop.add_task("haptic", 1, [&](const TickInfo& t) {
    ++haptic;
    last_t = t.t_s;
    if (t.index < 20) order.push_back('h');
  });
  loop.add_task("slave", 10, [&](const TickInfo& t) {
    ++slave;
    slave_dt = t.dt_s;
    if (t.index < 20) order.push_back('s');
  });
  loop.run_for(1000);
  EXPECT_EQ(haptic, 1000);
  EXPECT_EQ(slave, 100);
  EXPECT_DOUBLE_EQ(slave_dt, 1e-3);
  EXPECT_DOUBLE_EQ(last_t, 999 * 1e-4);
  EXPECT_EQ(order[0], 'h');
  EXPECT_EQ(order[1], 's');  // same tick: in the order added
  EXPECT_EQ(order[2], 'h');
  EXPECT_EQ(loop.ticks(), 1000u);
  EXPECT_EQ(loop.tick_stats().count(), 1000u);
}

TEST(FixedRateLoop, RunningNeverAllocates) {
  FixedRateLoop loop(10000.0);
  double acc = 0;
  loop.add_task("work", 1, [&](const TickInfo& t) { acc += t.t_s; });
  loop.add_task("slow", 7, [&](const TickInfo& t) { acc -= t.dt_s; });
  loop.run_for(10);  // warm-up
  std::size_t allocations = 0;
  {
    test::AllocationGuard guard;
    loop.run_for(20000);
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_NE(acc, 0.0);
}

TEST(FixedRateLoop, StopFromInsideATaskEndsTheRunAtThatTick) {
  FixedRateLoop loop(1000.0);
  loop.add_task("stopper", 1, [&](const TickInfo& t) {
    if (t.index == 41) loop.request_stop();
  });
  loop.run_for(1000);
  EXPECT_EQ(loop.ticks(), 42u);
}

TEST(FixedRateLoop, RealTimeRunIsPacedToTheWallClock) {
  FixedRateLoop loop(5000.0);
  int n = 0;
  loop.add_task("count", 1, [&](const TickInfo&) { ++n; });
  const auto start = std::chrono::steady_clock::now();
  loop.run_realtime(1000);  // 0.2 s
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(n, 1000);
  EXPECT_GE(wall, 0.195);
  EXPECT_LT(wall, 3.0);  // generous: shared CI machines
  EXPECT_EQ(loop.jitter_stats().count(), 1000u);
}

double thread_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// The two tick measures part where a tick is off the CPU: a tick that computes for 300 us costs
// the loop thread at least 300 us of CPU, a tick that waits 3 ms (as if preempted) lasts 3 ms on
// the wall clock and costs its thread next to nothing.
TEST(FixedRateLoop, TheTicksCpuTimeCountsComputeNotTimeOffTheCpu) {
  for (const bool realtime : {false, true}) {
    FixedRateLoop loop(100.0);
    std::vector<double> wall, cpu;
    wall.reserve(8), cpu.reserve(8);
    loop.add_task("work", 1, [&](const TickInfo& t) {
      if (t.index > 0) wall.push_back(loop.sampled_tick_s()), cpu.push_back(loop.sampled_tick_cpu_s());
      if (t.index % 2 == 0) {
        const double until = thread_cpu_s() + 300e-6;
        while (thread_cpu_s() < until) {
        }
      } else {
        std::this_thread::sleep_for(std::chrono::milliseconds(3));
      }
    });
    if (realtime)
      loop.run_realtime(7);
    else
      loop.run_for(7);
    ASSERT_EQ(cpu.size(), 6u);
    for (std::size_t i = 0; i < cpu.size(); ++i) {
      const bool computed = i % 2 == 0;  // the value read at tick i + 1 is tick i's
      SCOPED_TRACE(std::string(realtime ? "real time" : "simulation") + ", tick " + std::to_string(i));
      if (computed) {
        EXPECT_GE(cpu[i], 300e-6);
        EXPECT_LT(cpu[i], 5e-3);
      } else {
        EXPECT_GE(wall[i], 3e-3);
        // Half the tick's wall time: the sleep's own CPU (its call, under a sanitizer its
        // interception) is not the 3 ms off the CPU.
        EXPECT_LT(cpu[i], 0.5 * wall[i]) << "a tick off the CPU for 3 ms";
      }
    }
  }
}

// Sampling every third tick: the figures are those of ticks 0, 3, 6 (the heavy ones here), never
// of the light ticks between them.
TEST(FixedRateLoop, TheSampledTicksAreTheMultiplesOfTheDivisor) {
  FixedRateLoop loop(100.0);
  loop.sample_ticks_every(3);
  std::vector<double> cpu;
  cpu.reserve(16);
  loop.add_task("every third is heavy", 1, [&](const TickInfo& t) {
    if (t.index > 0) cpu.push_back(loop.sampled_tick_cpu_s());
    if (t.index % 3 == 0) {
      const double until = thread_cpu_s() + 300e-6;
      while (thread_cpu_s() < until) {
      }
    }
  });
  loop.run_for(9);
  ASSERT_EQ(cpu.size(), 8u);
  for (const double c : cpu) EXPECT_GE(c, 300e-6);
}

TEST(FixedRateLoop, RejectsBadRatesAndDivisors) {
  EXPECT_THROW(FixedRateLoop(0.0), InvalidParams);
  EXPECT_THROW(FixedRateLoop(-5.0), InvalidParams);
  FixedRateLoop loop(1000.0);
  EXPECT_THROW(loop.add_task("x", 0, [](const TickInfo&) {}), InvalidParams);
  EXPECT_THROW(loop.add_task("x", 1, TaskFn{}), InvalidParams);
  EXPECT_THROW(loop.sample_ticks_every(0), InvalidParams);
  EXPECT_THROW(loop.pin_to_core(-2), InvalidParams);
  try {
    loop.pin_to_core(CPU_SETSIZE);  // no such core
    FAIL();
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("loop.cpu"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(allowed_cores()), std::string::npos) << e.what();
  }
}

bool has_core(const cpu_set_t& set, int cpu) { return CPU_ISSET(cpu, &set); }

TEST(FixedRateLoop, APinnedLoopRunsOnItsCoreAndTheProcessKeepsOffItWhileItRuns) {
  cpu_set_t mine;
  ASSERT_EQ(sched_getaffinity(0, sizeof mine, &mine), 0);
  if (CPU_COUNT(&mine) < 2) GTEST_SKIP() << "one core: nowhere to move the other threads";
  int core = -1;
  for (int c = 0; c < CPU_SETSIZE; ++c)
    if (CPU_ISSET(c, &mine)) core = c;  // the last allowed core
  FixedRateLoop loop(2000.0);
  loop.pin_to_core(core);
  EXPECT_EQ(loop.pinned_core(), core);
  // A thread started before the run, as a server is: while the loop runs it keeps off the core.
  std::atomic<bool> quit{false}, off_during{true};
  std::atomic<int> checks{0};
  std::atomic<bool> running{false};
  std::thread server([&] {
    while (!quit.load()) {
      if (running.load()) {
        cpu_set_t s;
        sched_getaffinity(0, sizeof s, &s);
        if (has_core(s, core)) off_during = false;
        ++checks;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  });
  std::atomic<int> elsewhere{0}, ticks{0};
  loop.add_task("where", 1, [&](const TickInfo& t) {
    if (t.index == 100) running = true;   // the pinning is done before the first tick ...
    if (t.index == 380) running = false;  // ... and undone after the last
    if (sched_getcpu() != core) ++elsewhere;
    ++ticks;
  });
  loop.run_realtime(400);  // 0.2 s
  const int checked = checks.load();
  EXPECT_EQ(ticks.load(), 400);
  EXPECT_EQ(elsewhere.load(), 0) << "ticks run off core " << core;
  EXPECT_GT(checked, 0);
  EXPECT_TRUE(off_during.load()) << "a thread of the process ran on the loop's core";
  // Stopped: the core is given back to the process's threads.
  cpu_set_t after;
  ASSERT_EQ(sched_getaffinity(0, sizeof after, &after), 0);
  EXPECT_TRUE(has_core(after, core));
  quit = true;
  server.join();
}

}  // namespace
}  // namespace mc::runtime
