// Cost of the whole platform tick (goal: <= 50 us mean per 10 kHz tick on one core):
// three simulated stick-slip axes, the dual-stage interface with its rendering pipeline, the
// TéléTweez, the microworld, the teleoperation coupling, the slave controllers and the
// telemetry, as `microcobot run` steps them; and, in the same run, its main parts alone.
#include <benchmark/benchmark.h>

#include <array>
#include <memory>

#include "microcobot/cell/pick_place_operator.h"
#include "microcobot/platform/platform.h"

namespace {

namespace pf = mc::platform;

pf::PlatformConfig bench_config(bool tracking) {
  pf::PlatformConfig c;
  c.stage.tracking_enabled = tracking;
  return c;
}

struct Rig {
  explicit Rig(bool tracking = true) : config(bench_config(tracking)) {
    platform.set_operator([this](const mc::runtime::TickInfo& t) { op.act(t); });
  }
  pf::PlatformConfig config;
  pf::Platform platform{config};
  mc::cell::PickPlaceOperator op{platform, mc::cell::PickPlaceOperatorParams{}};
};

// Ticks of the scenario from `start_s` on: approach (0 s, one axis stepping) or transport
// (12 s, the part carried, x stepping at 100 um/s). The telemetry ring is drained outside
// the timing.
void platform_ticks(benchmark::State& state, double start_s, bool tracking = true) {
  auto rig = std::make_unique<Rig>(tracking);
  auto& loop = rig->platform.loop();
  if (start_s > 0) rig->platform.run(start_s);
  std::uint64_t n = 0;
  for (auto _ : state) {
    loop.run_for(1);
    if (++n % 4096 == 0) {
      state.PauseTiming();
      rig->platform.run(1e-4);  // drains the telemetry (and runs one more tick)
      state.ResumeTiming();
    }
  }
  state.counters["sim_time_s"] = loop.time_s();
}
void BM_PlatformTickApproach(benchmark::State& state) { platform_ticks(state, 0.0); }
void BM_PlatformTickTransport(benchmark::State& state) { platform_ticks(state, 12.0); }
BENCHMARK(BM_PlatformTickApproach)->Iterations(30000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_PlatformTickTransport)->Iterations(50000)->Unit(benchmark::kMicrosecond);
// The same with the hybrid position controller on the stage (stage.tracking_enabled: false).
void BM_PlatformTickApproachHybrid(benchmark::State& state) { platform_ticks(state, 0.0, false); }
void BM_PlatformTickTransportHybrid(benchmark::State& state) { platform_ticks(state, 12.0, false); }
BENCHMARK(BM_PlatformTickApproachHybrid)->Iterations(30000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_PlatformTickTransportHybrid)->Iterations(50000)->Unit(benchmark::kMicrosecond);

// The stick-slip share: three axes, ten 10 us model steps each, under a 2 kHz 60 V sawtooth.
void BM_ThreeAxesOneTick(benchmark::State& state) {
  const mc::stickslip::ActuatorModel model{mc::stickslip::StickSlipParams{}};
  std::array<mc::stickslip::ActuatorState, 3> s = {model.initial_state(), model.initial_state(),
                                                   model.initial_state()};
  for (auto& x : s) model.set_operating_point(x, 60.0, 2000.0, mc::stickslip::Direction::kForward);
  int k = 0;
  for (auto _ : state) {
    for (auto& x : s) {
      for (int i = 0; i < 10; ++i) {
        const int phase = (k + i) % 50;  // 50 steps of 10 us: slow rise, one-step drop
        model.step(x, phase == 49 ? 0.0 : 60.0 * phase / 48.0);
      }
    }
    k += 10;
    benchmark::DoNotOptimize(s[0].x2_m);
  }
}
BENCHMARK(BM_ThreeAxesOneTick)->Unit(benchmark::kMicrosecond);

// The masters' share: the dual-stage interface (pipeline + plant) and the TéléTweez.
void BM_MastersOneTick(benchmark::State& state) {
  mc::devices::SimulatedHapticMaster h("h", mc::haptics::DualStagePlantParams{},
                                       mc::haptics::RenderPipelineParams{}, mc::haptics::PantographParams{},
                                       1e-4);
  mc::devices::SimulatedTweezersMaster t("t", mc::tweezers::TeleTweezParams{}, 1e-4);
  for (mc::devices::Device* d : std::array<mc::devices::Device*, 2>{&h, &t}) {
    d->configure();
    d->activate();
  }
  h.set_operator({{0.0, 0.0}, true, false, 0.0});
  double f = 0.0;
  for (auto _ : state) {
    f = f > 0.1 ? 0.0 : f + 1e-4;
    h.command_force_N({f, f});
    h.update(1e-4);
    t.command_grip_force_N(f);
    t.update(1e-4);
    benchmark::DoNotOptimize(h.handle_position_m());
  }
}
BENCHMARK(BM_MastersOneTick)->Unit(benchmark::kMicrosecond);

}  // namespace
