// Cost of one 10 kHz tick of the rendering pipeline and of one plant step (must be << 100 us;
// the goal is < 1 us for RenderPipeline::tick()).
#include <cmath>

#include <benchmark/benchmark.h>

#include "microcobot/haptics/dual_stage_plant.h"
#include "microcobot/haptics/render_pipeline.h"

static void BM_RenderPipelineTick(benchmark::State& state) {
  mc::haptics::RenderPipeline rp{mc::haptics::RenderPipelineParams{}};
  double x = 0.0;
  for (auto _ : state) {
    x += 1e-3;
    benchmark::DoNotOptimize(rp.tick(std::sin(x)));
  }
}
BENCHMARK(BM_RenderPipelineTick);

static void BM_DualStagePlantStep(benchmark::State& state) {
  const mc::haptics::DualStagePlant plant{mc::haptics::DualStagePlantParams{}};
  mc::haptics::DualStagePlantState s;
  double x = 0.0;
  for (auto _ : state) {
    x += 1e-3;
    plant.step(s, 0.1 * std::sin(x), std::cos(x));
    benchmark::DoNotOptimize(s.accel_m_s2);
  }
}
BENCHMARK(BM_DualStagePlantStep);
