// Cost per control tick of the stick-slip controllers (docs/benchmarks.md, control section):
// update() once plus next_drive() for the 10 model steps of a 10 kHz tick at dt = 10 us; the
// plant is not included except in BM_XyzStageTick (three axes, model included).
#include <benchmark/benchmark.h>

#include "microcobot/control/position_controller.h"
#include "microcobot/control/velocity_controller.h"
#include "microcobot/control/xyz_stage.h"
#include "microcobot/stickslip/actuator.h"

namespace {

namespace ct = mc::control;
namespace ss = mc::stickslip;

const ss::ActuatorModel& model() {
  static const ss::ActuatorModel m{ss::StickSlipParams{}};
  return m;
}
const ct::StepMap& step_map() {
  static const ct::StepMap map{model()};
  return map;
}

void BM_VelocityControllerTick(benchmark::State& st) {
  ct::VelocityController c(ct::VelocityControlParams{}, ct::VelocityMode::kModelBased, &step_map());
  c.set_reference(100e-6);
  double x = 0.0;
  for (auto _ : st) {
    c.update(x);
    for (int i = 0; i < 10; ++i) x += 1e-12 * c.next_drive(1e-5).end_V;
    benchmark::DoNotOptimize(x);
  }
}
BENCHMARK(BM_VelocityControllerTick);

/// Position controller in a closed loop on the model, timed without the model's steps.
void position_tick(benchmark::State& st, double target) {
  ct::PositionController c(ct::PositionControlParams{}, model().params(), step_map());
  auto s = model().initial_state();
  c.set_target(target);
  mc::stickslip::DriveSegment u[10];
  for (auto _ : st) {
    c.update(model().slider_position(s));
    for (auto& v : u) v = c.next_drive(1e-5);
    st.PauseTiming();
    for (const auto& v : u) model().step(s, v);
    st.ResumeTiming();
  }
}
void BM_PositionControllerTickStepping(benchmark::State& st) { position_tick(st, 5e-3); }
void BM_PositionControllerTickScanning(benchmark::State& st) { position_tick(st, 0.5e-6); }
BENCHMARK(BM_PositionControllerTickStepping)->Iterations(20000);
BENCHMARK(BM_PositionControllerTickScanning)->Iterations(20000);

void BM_XyzStageTick(benchmark::State& st) {
  ct::XyzStage stage(model(), step_map());
  stage.set_target(ct::Axis::kX, 5e-3);
  stage.set_target(ct::Axis::kY, -5e-3);
  stage.set_target(ct::Axis::kZ, 0.3e-6);
  for (auto _ : st) stage.tick();
}
BENCHMARK(BM_XyzStageTick)->Iterations(20000);

}  // namespace
