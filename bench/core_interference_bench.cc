// What work on the other core does to a 10 kHz real-time loop on this one (why the
// camera thread lengthens the loop's heaviest ticks). The loop (SCHED_FIFO when allowed, pinned
// to the last core, spinning to each tick's start so that no wake-up cost enters the figure)
// times a fixed piece of work over a 512 kB working set, like a platform tick that stays in its
// core's L2; a second thread, pinned to core 0, spends alternating 400 ms
// windows doing one of:
//   idle      sleeping
//   compute   register-only arithmetic (a dependent chain: no memory)
//   l1        SIMD-friendly arithmetic over 4 kB (stays in L1)
//   l2        copies of 64 kB blocks within 256 kB (stays in L2)
//   stream    copies of 8 MB buffers (memory bandwidth: what a whole-frame renderer pass does)
// Counters: the tick's p99 (thread CPU time) per kind, 25 cycles of the five windows (the first
// 50 ms of each window not counted). A machine's own spells land in every kind alike.
// `build/release/bench/core_interference_bench` (docs/benchmarks.md, "Camera device").

#include <benchmark/benchmark.h>
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <ctime>
#include <string>
#include <thread>
#include <vector>

#include "microcobot/runtime/cpu_affinity.h"

namespace {

enum Kind : int { kIdle, kCompute, kL1, kL2, kStream, kKinds };
constexpr std::array<const char*, kKinds> kNames{"idle", "compute", "l1", "l2", "stream"};

double mono_s() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double thread_cpu_s() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// The other core's work for one kind, a few hundred microseconds at a time.
void disturb(int kind, std::vector<float>& a, std::vector<float>& b, double& x) {
  switch (kind) {
    case kIdle:
      std::this_thread::sleep_for(std::chrono::microseconds(200));
      break;
    case kCompute:
      for (int i = 0; i < 200000; ++i) x = x * 1.0000001 + 1e-9;
      break;
    case kL1:
      for (int r = 0; r < 2000; ++r)
        for (std::size_t i = 0; i < 1024; ++i) a[i] = a[i] * 1.0001f + b[i];
      break;
    case kL2:
      for (int r = 0; r < 32; ++r) std::memcpy(a.data() + (r % 4) * 16384, b.data(), 16384 * sizeof(float));
      break;
    default:
      std::memcpy(a.data(), b.data(), a.size() * sizeof(float));
      break;
  }
}

void BM_CoreInterference(benchmark::State& state) {
  const int cores = static_cast<int>(std::thread::hardware_concurrency());
  if (cores < 2) {
    state.SkipWithError("needs two cores");
    return;
  }
  for (auto _ : state) {
    std::atomic<int> kind{kIdle};
    std::atomic<bool> run{true};
    std::thread other([&] {
      mc::runtime::pin_calling_thread(0);
      std::vector<float> a(2u << 20, 1.0f), b(2u << 20, 2.0f);  // 8 MB each
      double x = 1.0;
      while (run.load(std::memory_order_relaxed)) disturb(kind.load(std::memory_order_relaxed), a, b, x);
      benchmark::DoNotOptimize(x);
    });
    std::array<std::vector<double>, kKinds> ticks;
    std::thread loop([&] {
      mc::runtime::pin_calling_thread(cores - 1);
      sched_param sp{};
      sp.sched_priority = sched_get_priority_max(SCHED_FIFO) - 10;
      pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);  // best effort (unprivileged: not)
      std::vector<double> working(64 * 1024, 1.0);             // 512 kB
      double next = mono_s();
      for (int cycle = 0; cycle < 25; ++cycle) {
        for (int k = 0; k < kKinds; ++k) {
          kind.store(k, std::memory_order_relaxed);
          const double start = mono_s() + 0.05, end = mono_s() + 0.4;
          while (mono_s() < end) {
            next += 1e-4;
            while (mono_s() < next) {
            }
            const double c0 = thread_cpu_s();
            double acc = 0;
            for (std::size_t i = 0; i < working.size(); i += 8) {
              acc += working[i];
              working[i] = acc * 1e-9 + 1.0;
            }
            for (int j = 0; j < 600; ++j) acc = std::sqrt(acc + j);
            benchmark::DoNotOptimize(acc);
            const double c1 = thread_cpu_s();
            if (mono_s() > start) ticks[static_cast<std::size_t>(k)].push_back(c1 - c0);
          }
        }
      }
    });
    loop.join();
    run.store(false);
    other.join();
    for (int k = 0; k < kKinds; ++k) {
      std::vector<double>& v = ticks[static_cast<std::size_t>(k)];
      std::sort(v.begin(), v.end());
      const auto at = [&](double q) {
        return 1e6 * v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
      };
      state.counters[std::string("p99_us_") + kNames[static_cast<std::size_t>(k)]] = at(0.99);
      state.counters[std::string("p50_us_") + kNames[static_cast<std::size_t>(k)]] = at(0.5);
    }
  }
}
BENCHMARK(BM_CoreInterference)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace
