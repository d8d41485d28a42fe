// Cost of the TéléTweez model step (the platform steps it inside its 10 kHz loop) and of the
// virtual-cube renderer update.
#include <benchmark/benchmark.h>

#include "microcobot/tweezers/teletweez.h"
#include "microcobot/tweezers/virtual_cube.h"

namespace {

void BM_TeleTweezStep(benchmark::State& state) {
  const mc::tweezers::TeleTweez model(mc::tweezers::TeleTweezParams{}, 1e-4);
  mc::tweezers::TeleTweezState s;
  mc::tweezers::Input u = mc::tweezers::Input::Zero();
  u[0] = 1e-3;
  for (auto _ : state) {
    model.step(s, u);
    benchmark::DoNotOptimize(s.q);
  }
}
BENCHMARK(BM_TeleTweezStep);

void BM_VirtualCubeUpdate(benchmark::State& state) {
  mc::tweezers::VirtualCubeRenderer r(mc::tweezers::TeleTweezParams{}, mc::tweezers::VirtualCubeParams{});
  double x = r.contact_closing();
  for (auto _ : state) {
    x += 1e-9;
    benchmark::DoNotOptimize(r.update(x));
  }
}
BENCHMARK(BM_VirtualCubeUpdate);

}  // namespace
