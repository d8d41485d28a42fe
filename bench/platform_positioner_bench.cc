// The platform's loop tick (every task of one 10 kHz tick: coupling, slave control, the devices'
// updates, telemetry) with the thesis's assembly, the parallel positioner's six legs beside the
// Cartesian robot (`positioner: parallel`), against the Cartesian robot alone, interleaved in one
// run while both move: p99 and median of each and their ratio (docs/benchmarks.md). Twice: the
// legs stepped on the loop (`parallel_positioner.controller: loop`), and on their controller's
// thread (`controller: thread`), where the loop only exchanges commands and poses with it.
//   build/<dir>/bench/platform_positioner_bench
#include <algorithm>
#include <chrono>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

#include <benchmark/benchmark.h>

#include "microcobot/motion/pose.h"
#include "microcobot/platform/platform.h"

namespace {

namespace pf = mc::platform;
constexpr double kDeg = std::numbers::pi / 180.0;

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

/// The console in control with its deadman, the Cartesian robot sent 0.3 mm along x and y.
void drive(pf::Platform& p) {
  mc::teleop::ConsoleInput in;
  in.active = in.fresh = in.deadman = true;
  in.has_goal = true;
  const auto& st = p.config().stage;
  in.goal_m = {st.home_x_m + 0.3e-3, st.home_y_m + 0.3e-3, st.home_z_m};
  in.goal_speed_m_s = 100e-6;
  p.set_console_input(in);
}

void PlatformTick(benchmark::State& state, const std::string& controller) {
  constexpr int kBlock = 100, kBlocks = 200;  // 20 000 ticks (2 s) of each
  std::vector<double> cart_s, both_s;
  for (auto _ : state) {
    pf::PlatformConfig c;
    c.devices.camera.driver = "none";
    pf::Platform cartesian(c);
    c.positioner = "parallel";
    c.parallel_positioner.controller = controller;
    pf::Platform both(c);
    for (pf::Platform* p : {&cartesian, &both}) {
      for (int k = 0; k < 2000; ++k) p->tick_for_test();  // the trackers power up
      // On its thread, they power up on the wall clock.
      for (int k = 0; k < 10000 && p->has_positioner() && !p->positioner()->at_rest(); ++k) {
        p->tick_for_test();
        std::this_thread::sleep_for(std::chrono::microseconds(100));
      }
      drive(*p);
    }
    // The 1 mm + 5 deg pose move of the motion benchmark.
    const mc::motion::PoseTrajectory t(
        both.positioner()->reference_pose(),
        mc::motion::to_transform(mc::motion::SmarPodPose{0.6e-3, 0.8e-3, 0.0, 3 * kDeg, 4 * kDeg, 0.0}),
        c.parallel_positioner.move);
    if (!mc::motion::check_move(both.positioner()->kinematics(), t).ok || !both.start_pose_move(t))
      state.SkipWithError("the pose move was refused");
    cart_s.clear();
    both_s.clear();
    for (int b = 0; b < kBlocks; ++b) {
      for (int k = 0; k < kBlock; ++k) {
        const auto t0 = std::chrono::steady_clock::now();
        cartesian.tick_for_test();
        cart_s.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
      for (int k = 0; k < kBlock; ++k) {
        const auto t0 = std::chrono::steady_clock::now();
        both.tick_for_test();
        both_s.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
    }
    if (!both.positioner()->moving()) state.SkipWithError("the pose move ended inside the measurement");
    // On its thread: the control periods it ran meanwhile, and the wakes that found it starved.
    if (const auto* ctl = both.simulation().positioner->controller()) {
      state.counters["controller_periods"] = static_cast<double>(ctl->view().periods);
      state.counters["controller_late_wakes"] = static_cast<double>(ctl->view().late_wakes);
    }
  }
  const double c50 = percentile(cart_s, 0.5), b50 = percentile(both_s, 0.5);
  const double c99 = percentile(cart_s, 0.99), b99 = percentile(both_s, 0.99);
  state.counters["cartesian_median_us"] = c50 * 1e6;
  state.counters["both_median_us"] = b50 * 1e6;
  state.counters["cartesian_p99_us"] = c99 * 1e6;
  state.counters["both_p99_us"] = b99 * 1e6;
  state.counters["ratio_median"] = b50 / c50;
  state.counters["ratio_p99"] = b99 / c99;
}
void PlatformTickWithTheParallelPositioner(benchmark::State& state) { PlatformTick(state, "loop"); }
void PlatformTickWithThePositionersControllerThread(benchmark::State& state) {
  PlatformTick(state, "thread");
}
BENCHMARK(PlatformTickWithTheParallelPositioner)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(PlatformTickWithThePositionersControllerThread)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace
