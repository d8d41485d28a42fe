// The parallel positioner's control tick (six stick-slip legs: model, sensor, tracker, the
// reference pose's IK and the measured and true poses' FK) against the XYZ stage's (three
// stick-slip axes with the hybrid position controller), interleaved in the same run: median and p99
// tick times of each and their ratio, and of the two together (the thesis's robot: the parallel
// positioner and the Cartesian one on one loop) against the XYZ stage alone (docs/benchmarks.md).
//   build/<dir>/bench/parallel_stage_bench
#include <algorithm>
#include <chrono>
#include <numbers>
#include <vector>

#include <benchmark/benchmark.h>

#include "microcobot/motion/parallel_stage.h"
#include "microcobot/motion/xyz_stage.h"

namespace {

namespace mm = mc::motion;
constexpr double kDeg = std::numbers::pi / 180.0;

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

void ParallelAgainstXyzTick(benchmark::State& state) {
  const mc::stickslip::ActuatorModel model{mc::stickslip::StickSlipParams{}};
  const mm::StepMap map(model);
  constexpr int kBlock = 100, kBlocks = 200;  // 20 000 ticks (2 s) of each
  std::vector<double> par_s, xyz_s, both_s;
  for (auto _ : state) {
    mm::ParallelStage par(model, map);
    mm::XyzStage xyz(model, map);
    mm::ParallelStage par2(model, map);
    mm::XyzStage xyz2(model, map);
    // Both moving: the 1 mm + 5 deg pose move, and each Cartesian axis 1 mm.
    par.move_to(mm::to_transform(mm::SmarPodPose{0.6e-3, 0.8e-3, 0.0, 3 * kDeg, 4 * kDeg, 0.0}));
    par2.move_to(mm::to_transform(mm::SmarPodPose{0.6e-3, 0.8e-3, 0.0, 3 * kDeg, 4 * kDeg, 0.0}));
    for (auto a : {mm::Axis::kX, mm::Axis::kY, mm::Axis::kZ}) {
      xyz.set_target(a, 1e-3);
      xyz2.set_target(a, 1e-3);
    }
    for (int k = 0; k < 200; ++k) {  // through the legs' power-up
      par.tick();
      par2.tick();
    }
    par_s.clear();
    xyz_s.clear();
    both_s.clear();
    for (int b = 0; b < kBlocks; ++b) {
      for (int k = 0; k < kBlock; ++k) {
        const auto t0 = std::chrono::steady_clock::now();
        par.tick();
        par_s.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
      for (int k = 0; k < kBlock; ++k) {
        const auto t0 = std::chrono::steady_clock::now();
        xyz.tick();
        xyz_s.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
      for (int k = 0; k < kBlock; ++k) {
        const auto t0 = std::chrono::steady_clock::now();
        par2.tick();
        xyz2.tick();
        both_s.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
    }
    benchmark::DoNotOptimize(par.true_pose().d.data());
  }
  const double pm = percentile(par_s, 0.5), xm = percentile(xyz_s, 0.5);
  const double p99 = percentile(par_s, 0.99), x99 = percentile(xyz_s, 0.99);
  state.counters["parallel_median_us"] = pm * 1e6;
  state.counters["xyz_median_us"] = xm * 1e6;
  state.counters["parallel_p99_us"] = p99 * 1e6;
  state.counters["xyz_p99_us"] = x99 * 1e6;
  state.counters["ratio_median"] = pm / xm;
  state.counters["ratio_p99"] = p99 / x99;
  state.counters["both_p99_us"] = percentile(both_s, 0.99) * 1e6;
  state.counters["both_over_xyz_p99"] = percentile(both_s, 0.99) / x99;
}
BENCHMARK(ParallelAgainstXyzTick)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace
