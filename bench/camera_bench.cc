// The speed goals for the camera device while the live platform runs (the loop paced,
// SCHED_FIFO, as `microcobot serve` runs it), in one run:
//  - the frame rate of 1280 x 1024 frames rendered and JPEG-encoded on the camera thread while
//    the camera is wanted (goal >= 30 fps), and the snapshot-to-JPEG latency;
//  - the loop's tick time p99 (the telemetry's tick_us, 1 kHz) with the camera forming frames
//    against the same loop with the camera idle, in alternating windows: 60 cycles of 1 s, each
//    400 ms counted with the camera wanted (after 50 ms for its first frame) and 400 ms counted
//    without (after 100 ms for the frame in progress to finish). A spell of the machine's lands
//    in either kind alike (docs/benchmarks.md, "Vendor-protocol twins", for why windows).
// Two placements (the argument): 0 the kernel places every thread; 1 the loop pinned to the last
// core (loop.cpu), the camera thread and the rest of the process kept off it.
// `build/release/bench/camera_bench` (docs/benchmarks.md). One iteration: the figures are counters.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <string_view>
#include <thread>
#include <vector>

#include "microcobot/live/live_platform.h"
#include "microcobot/runtime/timing_stats.h"
#include "telemetry_channel.h"

namespace {

using Clock = std::chrono::steady_clock;

void BM_CameraCostOnTheLoop(benchmark::State& state) {
  const bool pinned = state.range(0) != 0;
  for (auto _ : state) {
    mc::live::LiveParams lp;
    // Pinned: the loop on the last core, the camera thread (and the rest of the process) off it.
    if (pinned) lp.platform.loop.cpu = static_cast<int>(std::thread::hardware_concurrency()) - 1;
    mc::live::LivePlatform live(lp);
    const std::size_t tick_channel = mc::bench::telemetry_channel("tick_us");
    std::atomic<int> phase{-1};  // -1 not counted; 0 camera idle; 1 camera forming frames
    std::array<mc::runtime::TimingStats, 2> ticks{mc::runtime::TimingStats(1e-7),
                                                  mc::runtime::TimingStats(1e-7)};  // drain thread only
    std::atomic<std::uint64_t> frames_counted{0}, bytes{0};
    mc::runtime::TimingStats latency(1e-4), capture(1e-4);  // camera thread only
    live.set_frame_sink([&](const mc::devices::CameraFrame& f, double) {
      if (phase.load(std::memory_order_relaxed) != 1) return;
      frames_counted.fetch_add(1, std::memory_order_relaxed);
      bytes.fetch_add(f.jpeg.size(), std::memory_order_relaxed);
      latency.add(f.latency_s);
      capture.add(f.capture_s + f.encode_s);
    });
    live.set_camera_wanted(false);
    live.start([&](const mc::platform::TelemetrySample& s, std::size_t) {
      const int p = phase.load(std::memory_order_relaxed);
      if (p >= 0) ticks[static_cast<std::size_t>(p)].add(1e-6 * s[tick_channel]);
    });
    std::this_thread::sleep_for(std::chrono::seconds(1));  // warm-up
    double on_s = 0.0;
    auto at = Clock::now();
    for (int c = 0; c < 60; ++c) {
      live.set_camera_wanted(true);
      std::this_thread::sleep_until(at += std::chrono::milliseconds(50));
      const auto on0 = Clock::now();
      phase.store(1);
      std::this_thread::sleep_until(at += std::chrono::milliseconds(400));
      phase.store(-1);
      on_s += std::chrono::duration<double>(Clock::now() - on0).count();
      live.set_camera_wanted(false);
      std::this_thread::sleep_until(at += std::chrono::milliseconds(100));
      phase.store(0);
      std::this_thread::sleep_until(at += std::chrono::milliseconds(400));
      phase.store(-1);
      std::this_thread::sleep_until(at += std::chrono::milliseconds(50));
    }
    live.stop();
    const double n = static_cast<double>(frames_counted.load());
    state.counters["fps_while_wanted"] = n / on_s;
    state.counters["frame_kB"] = n > 0 ? 1e-3 * static_cast<double>(bytes.load()) / n : 0.0;
    state.counters["render_encode_ms_p50"] = 1e3 * capture.quantile_s(0.5);
    state.counters["latency_ms_p50"] = 1e3 * latency.quantile_s(0.5);
    state.counters["latency_ms_p95"] = 1e3 * latency.quantile_s(0.95);
    state.counters["tick_p99_idle_us"] = 1e6 * ticks[0].quantile_s(0.99);
    state.counters["tick_p99_camera_us"] = 1e6 * ticks[1].quantile_s(0.99);
    state.counters["tick_p99_ratio"] = ticks[1].quantile_s(0.99) / ticks[0].quantile_s(0.99);
    state.counters["tick_p90_idle_us"] = 1e6 * ticks[0].quantile_s(0.9);
    state.counters["tick_p90_camera_us"] = 1e6 * ticks[1].quantile_s(0.9);
    state.counters["tick_samples_idle"] = static_cast<double>(ticks[0].count());
  }
}
BENCHMARK(BM_CameraCostOnTheLoop)
    ->ArgName("pinned")
    ->Arg(0)
    ->Arg(1)
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

}  // namespace
