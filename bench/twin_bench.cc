// A vendor twin's cost, on the live platform (paced loop) in one run, for the GCS 2.0 twin, the
// MCS2 twin and the PI C-887 hexapod twin on the platform with the parallel positioner (the
// benchmark's second argument, 0, 1 and 2):
//  - command-to-reply latency of a position query over loopback TCP (four clients polling at
//    100 Hz): GCS `POS?` (every axis, one line each), MCS2 `:CHAN0:POS?;:CHAN1:POS?;:CHAN2:POS?`
//    (three replies, one line each), the hexapod's `POS? X Y Z U V W` (the pose's forward
//    kinematics from the legs' sensors, six lines);
//  - the loop's tick time p99 (the telemetry's tick_us) while those four clients poll, against
//    the same loop with no client, in alternating 40 ms windows (240 of each, 9.6 s each in all):
//    a machine's hiccup (another tenant, a page-cache flush) lands in either kind alike.
// Three placements (the benchmark's argument):
//  0  the loop not pinned (the kernel places every thread);
//  1  the loop pinned to the last core (loop.cpu), the clients free to run anywhere, as other
//     processes on a machine whose core is not isolated;
//  2  the loop pinned and the clients kept off its core with the rest of the process, as on a
//     machine whose loop core is isolated (isolcpus=, a cpuset).
// `build/release/bench/twin_bench` (docs/benchmarks.md). One iteration: the figures are counters.

#include <benchmark/benchmark.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sched.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "microcobot/live/live_platform.h"
#include "microcobot/runtime/timing_stats.h"
#include "microcobot/twins/live_stage.h"
#include "microcobot/twins/twin_server.h"
#include "telemetry_channel.h"

namespace {

using Clock = std::chrono::steady_clock;

int connect_loopback(std::uint16_t port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  int one = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  return fd;
}

// One position query's round trip, the whole reply read.
struct PositionQuery {
  std::string text;
  // Whether `reply` is whole: GCS ends its last line without a space before the line feed; MCS2
  // answers each of the three queries with one line.
  bool (*complete)(const std::string& reply);
};

const PositionQuery& position_query(mc::twins::Protocol protocol) {
  static const PositionQuery gcs2{"POS?\n", [](const std::string& r) {
                                    return r.size() >= 2 && r.back() == '\n' && r[r.size() - 2] != ' ';
                                  }};
  static const PositionQuery mcs2{":CHAN0:POS?;:CHAN1:POS?;:CHAN2:POS?\r\n", [](const std::string& r) {
                                    return std::count(r.begin(), r.end(), '\n') == 3;
                                  }};
  static const PositionQuery hexapod{"POS? X Y Z U V W\n", gcs2.complete};
  switch (protocol) {
    case mc::twins::Protocol::kMcs2:
      return mcs2;
    case mc::twins::Protocol::kGcs2Hexapod:
      return hexapod;
    default:
      return gcs2;
  }
}

bool pos_query(int fd, const PositionQuery& q) {
  if (::send(fd, q.text.data(), q.text.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(q.text.size()))
    return false;
  std::string text;
  char buf[512];
  while (!q.complete(text)) {
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) return false;
    text.append(buf, static_cast<std::size_t>(n));
  }
  return true;
}

// Lets the calling thread run on every core (an outside process's client).
void allow_every_core() {
  cpu_set_t set;
  CPU_ZERO(&set);
  for (unsigned c = 0; c < std::thread::hardware_concurrency(); ++c) CPU_SET(c, &set);
  sched_setaffinity(0, sizeof set, &set);
}

void BM_TwinPollingCost(benchmark::State& state) {
  const int placement = static_cast<int>(state.range(0));
  constexpr std::array kProtocols{mc::twins::Protocol::kGcs2, mc::twins::Protocol::kMcs2,
                                  mc::twins::Protocol::kGcs2Hexapod};
  const auto protocol = kProtocols.at(static_cast<std::size_t>(state.range(1)));
  state.SetLabel(mc::twins::protocol_name(protocol));
  const PositionQuery& query = position_query(protocol);
  const int last_core = static_cast<int>(std::thread::hardware_concurrency()) - 1;
  for (auto _ : state) {
    mc::live::LiveParams lp;
    if (placement > 0) lp.platform.loop.cpu = last_core;
    if (protocol == mc::twins::Protocol::kGcs2Hexapod) lp.platform.positioner = "parallel";
    mc::live::LivePlatform live(lp);
    // Nobody watches the microscope (as `serve` without a console open or a recording): the
    // simulated camera renders no frame. Rendering one (a third of a core, the simulation's cost,
    // not a real camera's) took the unpinned replies' p99 from about 1 ms to 2.6-3.9 ms.
    live.set_camera_wanted(false);
    const std::size_t tick_channel = mc::bench::telemetry_channel("tick_us");
    std::atomic<int> phase{-1};  // -1 not counted; 0 idle; 1 polled
    std::array<mc::runtime::TimingStats, 2> ticks{mc::runtime::TimingStats(1e-7),
                                                  mc::runtime::TimingStats(1e-7)};  // drain thread only
    live.start([&](const mc::platform::TelemetrySample& s, std::size_t) {
      const int p = phase.load(std::memory_order_relaxed);
      if (p >= 0) ticks[static_cast<std::size_t>(p)].add(1e-6 * s[tick_channel]);
    });
    mc::twins::LiveStage stage(live);
    mc::twins::TwinServerParams tp;
    tp.endpoints = {{protocol, "127.0.0.1", 0}};
    mc::twins::TwinServer server(stage, tp);
    server.start();
    const std::uint16_t port = server.ports()[0];

    mc::runtime::TimingStats latency(1e-6);  // 1 us bins
    std::atomic<bool> polling{false}, quit{false};
    std::vector<std::vector<double>> samples(4);
    std::vector<std::thread> clients;
    for (int k = 0; k < 4; ++k) {
      clients.emplace_back([&, k] {
        if (placement == 1) allow_every_core();
        const int fd = connect_loopback(port);
        auto next = Clock::now();
        while (!quit.load()) {
          next += std::chrono::milliseconds(10);  // 100 Hz
          std::this_thread::sleep_until(next);
          if (!polling.load()) continue;
          const auto t0 = Clock::now();
          if (!pos_query(fd, query)) break;
          samples[static_cast<std::size_t>(k)].push_back(
              std::chrono::duration<double>(Clock::now() - t0).count());
        }
        ::close(fd);
      });
    }
    std::this_thread::sleep_for(std::chrono::seconds(1));  // warm-up
    // 240 cycles of 100 ms: 40 ms counted idle, 10 ms for the clients to start, 40 ms counted
    // polled, 10 ms for their last replies. A spell of the machine's (the 2-core VM's tick time
    // jumps from ~6 to ~40 us for seconds at a time, clients or not) spans both kinds of window.
    auto at = Clock::now();
    for (int c = 0; c < 240; ++c) {
      phase.store(0);
      std::this_thread::sleep_until(at += std::chrono::milliseconds(40));
      phase.store(-1);
      polling.store(true);
      std::this_thread::sleep_until(at += std::chrono::milliseconds(10));
      phase.store(1);
      std::this_thread::sleep_until(at += std::chrono::milliseconds(40));
      phase.store(-1);
      polling.store(false);
      std::this_thread::sleep_until(at += std::chrono::milliseconds(10));
    }
    quit.store(true);
    for (auto& t : clients) t.join();
    server.stop();
    live.stop();
    for (const auto& v : samples)
      for (double s : v) latency.add(s);
    state.counters["pos_latency_p50_ms"] = 1e3 * latency.quantile_s(0.5);
    state.counters["pos_latency_p99_ms"] = 1e3 * latency.quantile_s(0.99);
    state.counters["pos_latency_max_ms"] = 1e3 * latency.max_s();
    state.counters["pos_queries"] = static_cast<double>(latency.count());
    state.counters["tick_p99_idle_us"] = 1e6 * ticks[0].quantile_s(0.99);
    state.counters["tick_p99_polled_us"] = 1e6 * ticks[1].quantile_s(0.99);
    state.counters["tick_p99_ratio"] = ticks[1].quantile_s(0.99) / ticks[0].quantile_s(0.99);
    state.counters["tick_p90_idle_us"] = 1e6 * ticks[0].quantile_s(0.9);
    state.counters["tick_p90_polled_us"] = 1e6 * ticks[1].quantile_s(0.9);
    state.counters["tick_samples_idle"] = static_cast<double>(ticks[0].count());
    state.counters["overruns"] = static_cast<double>(live.status().overruns);
  }
}
BENCHMARK(BM_TwinPollingCost)
    ->ArgNames({"placement", "protocol"})
    ->ArgsProduct({{0, 1, 2}, {0, 1, 2}})
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

}  // namespace
