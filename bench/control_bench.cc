// Cost per control tick of the stick-slip controllers (docs/benchmarks.md, control section):
// update() once plus next_drive() for the 10 model steps of a 10 kHz tick at dt = 10 us; the
// plant is not included except in BM_XyzStageTick (three axes, model included).
#include <benchmark/benchmark.h>

#include "microcobot/motion/position_controller.h"
#include "microcobot/motion/setpoint_stream.h"
#include "microcobot/motion/tracking_controller.h"
#include "microcobot/motion/velocity_controller.h"
#include "microcobot/motion/xyz_stage.h"
#include "microcobot/stickslip/actuator.h"
#include "microcobot/teleop/contact_estimator.h"
#include "microcobot/teleop/delayed_teleoperation.h"
#include "microcobot/teleop/model_mediated_master.h"

namespace {

namespace ss = mc::stickslip;

const ss::ActuatorModel& model() {
  static const ss::ActuatorModel m{ss::StickSlipParams{}};
  return m;
}
const mc::motion::StepMap& step_map() {
  static const mc::motion::StepMap map{model()};
  return map;
}

void BM_VelocityControllerTick(benchmark::State& st) {
  mc::motion::VelocityController c(mc::motion::VelocityControlParams{}, mc::motion::VelocityMode::kModelBased,
                                   &step_map());
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
  mc::motion::PositionController c(mc::motion::PositionControlParams{}, model().params(), step_map());
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

/// Tracking controller following a 200 um/s ramp on the model (edges every ~2.5 ms),
/// timed without the model's steps.
void BM_TrackingControllerTick(benchmark::State& st) {
  mc::motion::TrackingController c(mc::motion::TrackingParams{}, model().params(), step_map());
  auto s = model().initial_state();
  c.reset(0.0, 0.0);
  double r = 0.0;
  mc::stickslip::DriveSegment u[10];
  for (auto _ : st) {
    r += 200e-6 * 1e-4;
    c.set_reference({r, 200e-6, 0.0});
    c.update(model().slider_position(s));
    for (auto& v : u) v = c.next_drive(1e-5);
    st.PauseTiming();
    model().set_operating_point(s, c.operating_point().amplitude_V, c.operating_point().frequency_Hz,
                                c.operating_point().direction);
    for (const auto& v : u) model().step(s, v);
    st.ResumeTiming();
  }
}
BENCHMARK(BM_TrackingControllerTick)->Iterations(20000);

/// Setpoint stream: one setpoint per 10 ticks (1 kHz) and a sample per tick (10 kHz).
void BM_SetpointStreamSample(benchmark::State& st) {
  mc::motion::SetpointStream s(mc::motion::SetpointStreamParams{}, 0.0);
  long k = 0;
  for (auto _ : st) {
    const double t = static_cast<double>(k) * 1e-4;
    if (k % 10 == 0) s.push(t, 1e-9 * static_cast<double>(k));
    benchmark::DoNotOptimize(s.sample(t, 1e-4));
    ++k;
  }
}
BENCHMARK(BM_SetpointStreamSample);

void BM_XyzStageTick(benchmark::State& st) {
  mc::motion::XyzStage stage(model(), step_map());
  stage.set_target(mc::motion::Axis::kX, 5e-3);
  stage.set_target(mc::motion::Axis::kY, -5e-3);
  stage.set_target(mc::motion::Axis::kZ, 0.3e-6);
  for (auto _ : st) stage.tick();
}
BENCHMARK(BM_XyzStageTick)->Iterations(20000);

/// Model-mediated teleoperation: the master model's haptic step (eq. 1-3 of
/// model_mediated_master.h, with its passivity controller) and the slave estimator's sample.
void BM_ModelMediatedMasterStep(benchmark::State& st) {
  mc::teleop::ModelMediatedMaster m({}, {0.0, 0.02, 1000.0});
  m.receive({0.0, 0.0201, 1200.0});
  double x = 0.021, v = 1e-3, acc = 0.0;
  for (auto _ : st) {
    acc += m.force(x, v, 1e-4);
    v = -v;  // in and out: the controller's branch taken as often as not
    x += v * 1e-4;
    benchmark::DoNotOptimize(acc);
  }
}
BENCHMARK(BM_ModelMediatedMasterStep);

void BM_ContactEstimatorUpdate(benchmark::State& st) {
  mc::teleop::ContactEstimator e({}, {0.0, 0.02, 1000.0});
  double x = 0.02, dx = 1e-6;
  for (auto _ : st) {
    e.update(x, 1500.0 * (x - 0.0199));
    x += dx;
    if (x > 0.0205 || x < 0.02) dx = -dx;
    benchmark::DoNotOptimize(e.model().stiffness_N_m);
  }
}
BENCHMARK(BM_ContactEstimatorUpdate);

/// One delay-sweep case (6 s of the coupling at 1 kHz, mechanics at 10 kHz), per scheme.
void BM_DelayCase(benchmark::State& st) {
  const auto scheme = static_cast<mc::teleop::Scheme>(st.range(0));
  for (auto _ : st) {
    const auto r =
        mc::teleop::run_delay_case(mc::teleop::DelayedTeleopParams{}, {0.2, 0.01, 0.2, scheme, 1, 0.0});
    benchmark::DoNotOptimize(r.max_handle_excursion_m);
  }
}
BENCHMARK(BM_DelayCase)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

}  // namespace
