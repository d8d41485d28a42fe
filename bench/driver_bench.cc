// Does a driver-backed platform keep its 1 kHz slave control rate against the twin?
// One run: the GCS 2.0 twin (the live platform, paced, with its TCP server) runs throughout; in
// alternating 2 s phases (three of each) this process runs, paced to the wall clock, either the
// simulated platform (no driver) or a platform whose axes are `pi-gcs2` on that twin (and, in the
// second benchmark, `smaract-mcs2` on the MCS2 twin), the console
// moving the stage between two goals 20 um apart every 0.5 s (MOV traffic). The third: the
// platform with the parallel positioner, simulated or `pi-hexapod` on the PI C-887 hexapod twin
// (a live platform with the parallel positioner), the console's deadman held and the positioner
// sent between two poses 20 um apart along x every 0.5 s (pose moves). Per phase: loop ticks
// per wall second, slave-control ticks per second (ticks / loop.slave_divisor), the loop's tick
// time p99 and overruns; for the driver, its bus cycles per second (MOV + ERR? + POS?) and the
// share of operator ticks (1 kHz) whose measurement was fresh; the pose moves started.
// `build/release/bench/driver_bench` (docs/benchmarks.md). One iteration: the figures are counters.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <string>

#include <fmt/format.h>

#include "microcobot/drivers/bus_controller.h"
#include "microcobot/drivers/pi_hexapod.h"
#include "microcobot/drivers/register_drivers.h"
#include "microcobot/live/live_platform.h"
#include "microcobot/motion/pose.h"
#include "microcobot/platform/driver_registry.h"
#include "microcobot/twins/live_stage.h"
#include "microcobot/twins/twin_server.h"

namespace {

using Clock = std::chrono::steady_clock;

struct Phase {
  double ticks_per_s = 0, slave_per_s = 0, tick_p99_us = 0, overruns = 0, bus_cycles_per_s = 0, fresh = 0;
  double pose_moves = 0;
};

// The controller whose bus the phase measures: the Cartesian axes' or the positioner's (null: a
// simulated platform).
const mc::drivers::BusController* bus_of(const mc::platform::Platform& p, bool positioner) {
  if (positioner) {
    const auto* h = dynamic_cast<const mc::drivers::PiHexapod*>(p.positioner());
    return h != nullptr ? &h->controller() : nullptr;
  }
  const auto* axis = dynamic_cast<const mc::drivers::BusAxis*>(&p.axis(0));
  return axis != nullptr ? &axis->controller() : nullptr;
}

// `positioner`: pose moves of the parallel positioner between x = +-10 um (from where it holds when
// the phase starts, then back and forth: the trajectories planned here, off the loop), else the
// Cartesian stage's goals.
Phase run_phase(mc::platform::Platform& p, double seconds, bool positioner) {
  const auto& s = p.config().stage;
  const Eigen::Vector3d home(s.home_x_m, s.home_y_m, s.home_z_m);
  mc::teleop::ConsoleInput in;
  in.active = in.fresh = in.deadman = true;
  in.has_goal = !positioner;
  in.goal_speed_m_s = 1e-3;
  namespace mm = mc::motion;
  const mm::PoseMoveLimits& lim = p.config().parallel_positioner.move;
  const mm::PlatformTransform right = mm::to_transform(mm::SmarPodPose{10e-6, 0, 0, 0, 0, 0}),
                              left = mm::to_transform(mm::SmarPodPose{-10e-6, 0, 0, 0, 0, 0});
  const mm::PlatformTransform held = positioner ? p.positioner()->reference_pose() : mm::PlatformTransform{};
  const std::array<mm::PoseTrajectory, 3> moves{mm::PoseTrajectory(held, right, lim),
                                                mm::PoseTrajectory(right, left, lim),
                                                mm::PoseTrajectory(left, right, lim)};
  std::size_t next_move = 0;
  long long last_slot = -1;
  std::uint64_t slave_ticks = 0, fresh_ticks = 0, pose_moves = 0;
  const int divisor = p.config().loop.slave_divisor;
  const mc::drivers::BusController* bus = bus_of(p, positioner);
  p.set_operator([&](const mc::runtime::TickInfo& t) {
    const long long slot = static_cast<long long>(t.t_s / 0.5);
    in.goal_m = home + Eigen::Vector3d(slot % 2 == 0 ? 10e-6 : -10e-6, 0, 0);
    p.set_console_input(in);
    // The move that starts where the positioner holds: the next one first.
    for (std::size_t k = 0; positioner && slot != last_slot && k < moves.size() && p.positioner()->at_rest();
         ++k) {
      const std::size_t m = (next_move + k) % moves.size();
      if (!p.start_pose_move(moves[m])) continue;
      last_slot = slot;
      next_move = m == 2 ? 1 : m + 1;
      ++pose_moves;
    }
    ++slave_ticks;  // the operator task's rate (1 kHz, as the slave's)
    fresh_ticks += (bus != nullptr ? bus->fresh() : p.axis(0).measurement_fresh()) ? 1 : 0;
  });
  const std::uint64_t cycles0 = bus != nullptr ? bus->cycles() : 0;
  const std::uint64_t ticks0 = p.loop().ticks(), over0 = p.loop().overruns();
  const auto t0 = Clock::now();
  p.run(seconds);
  const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
  Phase r;
  r.ticks_per_s = static_cast<double>(p.loop().ticks() - ticks0) / wall;
  r.slave_per_s = r.ticks_per_s / divisor;
  r.tick_p99_us = 1e6 * p.loop().tick_stats().quantile_s(0.99);
  r.overruns = static_cast<double>(p.loop().overruns() - over0);
  if (bus != nullptr) r.bus_cycles_per_s = static_cast<double>(bus->cycles() - cycles0) / wall;
  r.fresh = slave_ticks > 0 ? static_cast<double>(fresh_ticks) / static_cast<double>(slave_ticks) : 0.0;
  r.pose_moves = static_cast<double>(pose_moves);
  return r;
}

// The phases against the twin's `protocol` port, the driver set `driver` on it (the parallel
// positioner's with the hexapod twin, the Cartesian axes' otherwise).
void driver_backed_rate(benchmark::State& state, mc::twins::Protocol protocol, const char* driver) {
  mc::drivers::register_vendor_drivers();
  const bool positioner = protocol == mc::twins::Protocol::kGcs2Hexapod;
  for (auto _ : state) {
    mc::live::LiveParams lp;
    if (positioner) lp.platform.positioner = "parallel";
    mc::live::LivePlatform live(lp);
    live.start([](const mc::platform::TelemetrySample&, std::size_t) {});
    mc::twins::LiveStage stage(live);
    mc::twins::TwinServerParams tp;
    tp.endpoints = {{protocol, "127.0.0.1", 0}};
    mc::twins::TwinServer server(stage, tp);
    server.start();
    mc::platform::PlatformConfig sim;
    sim.loop.realtime = true;
    if (positioner) sim.positioner = "parallel";
    mc::platform::PlatformConfig drv = sim;
    if (positioner) {
      drv.parallel_positioner.driver = driver;
      drv.parallel_positioner.connection = fmt::format("127.0.0.1:{}", server.ports()[0]);
    } else {
      drv.devices.driver = driver;
      drv.devices.connection = fmt::format("127.0.0.1:{},velocity_mm_s=1", server.ports()[0]);
    }
    std::array<Phase, 2> sum{};  // [0] simulated, [1] driver
    for (int k = 0; k < 6; ++k) {
      const bool with_driver = k % 2 == 1;
      // A new platform each phase: its loop's statistics are that phase's.
      auto p = mc::platform::make_platform(with_driver ? drv : sim);
      const Phase r = run_phase(*p, 2.0, positioner);
      Phase& a = sum[with_driver ? 1 : 0];
      a.ticks_per_s += r.ticks_per_s / 3;
      a.slave_per_s += r.slave_per_s / 3;
      a.tick_p99_us += r.tick_p99_us / 3;
      a.overruns += r.overruns;
      a.bus_cycles_per_s += r.bus_cycles_per_s / 3;
      a.fresh += r.fresh / 3;
      a.pose_moves += r.pose_moves;
      if (with_driver && p->faulted()) state.SkipWithError("the driver faulted");
    }
    server.stop();
    live.stop();
    state.counters["sim_ticks_per_s"] = sum[0].ticks_per_s;
    state.counters["drv_ticks_per_s"] = sum[1].ticks_per_s;
    state.counters["sim_slave_ticks_per_s"] = sum[0].slave_per_s;
    state.counters["drv_slave_ticks_per_s"] = sum[1].slave_per_s;
    state.counters["rate_ratio"] = sum[1].ticks_per_s / sum[0].ticks_per_s;
    state.counters["sim_tick_p99_us"] = sum[0].tick_p99_us;
    state.counters["drv_tick_p99_us"] = sum[1].tick_p99_us;
    state.counters["tick_p99_ratio"] = sum[1].tick_p99_us / sum[0].tick_p99_us;
    state.counters["sim_overruns"] = sum[0].overruns;
    state.counters["drv_overruns"] = sum[1].overruns;
    state.counters["drv_bus_cycles_per_s"] = sum[1].bus_cycles_per_s;
    state.counters["drv_fresh_share"] = sum[1].fresh;
    if (positioner) {
      state.counters["sim_pose_moves"] = sum[0].pose_moves;
      state.counters["drv_pose_moves"] = sum[1].pose_moves;
    }
  }
}
void BM_DriverBackedPlatformRate(benchmark::State& state) {
  driver_backed_rate(state, mc::twins::Protocol::kGcs2, "pi-gcs2");
}
BENCHMARK(BM_DriverBackedPlatformRate)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();
// The same on `smaract-mcs2` against the MCS2 twin: its bus cycle is one round trip per query
// (:SYST:ERR:COUN? and three :CHAN<n>:POS?, the :MOVEs written with the first).
void BM_Mcs2DriverBackedPlatformRate(benchmark::State& state) {
  driver_backed_rate(state, mc::twins::Protocol::kMcs2, "smaract-mcs2");
}
BENCHMARK(BM_Mcs2DriverBackedPlatformRate)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();
// The parallel positioner on `pi-hexapod` against the hexapod twin: its bus cycle polls the pose
// (POS? X Y Z U V W, #5) and writes each pose move (VLS, MOV) with its ERR?.
void BM_PiHexapodDriverBackedPlatformRate(benchmark::State& state) {
  driver_backed_rate(state, mc::twins::Protocol::kGcs2Hexapod, "pi-hexapod");
}
BENCHMARK(BM_PiHexapodDriverBackedPlatformRate)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace
