// Open-loop stepping on the platform (the ANC300's stepu/stepd): n sawtooth periods
// through the stick-slip model move the axis what the model alone moves for the same drive, end
// holding, and obey the safety rules (deadman, fault, e-stop); the rotary axis
// too, on its rotor's arc, within its travel.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "microcobot/platform/platform.h"
#include "microcobot/stickslip/actuator.h"
#include "microcobot/stickslip/drive.h"

namespace mc::devices {
namespace {

struct SteppingRig {
  platform::PlatformConfig config;
  std::unique_ptr<platform::Platform> platform;
  teleop::ConsoleInput in;
  SteppingRig() {
    platform = std::make_unique<platform::Platform>(config);
    in.active = true;
    in.fresh = true;
    in.deadman = true;
    platform->set_operator([this](const runtime::TickInfo&) { platform->set_console_input(in); });
    platform->set_console_input(in);
    platform->run(0.05);  // settled in hold
  }
  double true_x() const { return platform->simulation().axes[0]->true_position_m(); }
};

// The slider's position after each of `periods` periods of the sawtooth, as `stickslip simulate`
// runs it from rest (index 0: before the first).
std::vector<double> model_positions(const platform::PlatformConfig& config, double amplitude_V,
                                    double frequency_Hz, stickslip::Direction dir, int periods) {
  const stickslip::ActuatorModel m(platform::axis_params(config));
  const auto w = stickslip::make_waveform(stickslip::WaveKind::kSawtooth, amplitude_V, frequency_Hz, dir,
                                          m.params().drive);
  stickslip::ActuatorState s = m.initial_state();
  std::vector<double> x(static_cast<std::size_t>(periods) + 1, m.slider_position(s));
  std::size_t next = 1;  // x[k]: the first sample at or after k periods
  stickslip::simulate_each(
      m, w, periods / frequency_Hz + m.dt_s(), 1, s, [&](const stickslip::ActuatorState& st) {
        while (next < x.size() && st.t_s >= static_cast<double>(next) / frequency_Hz - 1e-12)
          x[next++] = m.slider_position(st);
      });
  return x;
}

constexpr double kAmplitude_V = 60.0, kFrequency_Hz = 500.0;
constexpr int kPeriods = 100, kTransient = 10;

// The steady stepping (periods 10 to 100) is what the model steps: the first periods differ by
// construction (the model starts from rest with its power-up transient, the axis from its hold
// voltage through the entry edge). 15%: the two runs' hysteresis and contact states differ.
// Axis 3, the rotary axis, steps the same arc on its rotor.
void expect_steps_like_the_model(int axis, int direction) {
  SteppingRig rig;
  const auto& sims = rig.platform->simulation();
  const auto& sim = axis < 3 ? *sims.axes[static_cast<std::size_t>(axis)] : *sims.rotary;
  const double x0 = sim.true_position_m();
  ASSERT_TRUE(rig.platform->start_open_loop_steps(axis, kAmplitude_V, kFrequency_Hz, direction, kPeriods));
  EXPECT_TRUE(rig.platform->open_loop_running(axis));
  rig.platform->run(kTransient / kFrequency_Hz);
  const double x_transient = sim.true_position_m();
  // To the run's end (within a tick of 1 ms), before the position loop takes the axis back.
  rig.platform->run((kPeriods - kTransient) / kFrequency_Hz);
  for (int k = 0; k < 10 && rig.platform->open_loop_running(axis); ++k) rig.platform->run(0.001);
  EXPECT_FALSE(rig.platform->open_loop_running(axis));
  const double x_end = sim.true_position_m();
  const auto model = model_positions(
      rig.config, kAmplitude_V, kFrequency_Hz,
      direction > 0 ? stickslip::Direction::kForward : stickslip::Direction::kBackward, kPeriods);
  const double steady = x_end - x_transient, model_steady = model[kPeriods] - model[kTransient];
  std::printf(
      "open loop axis %d dir %+d: first %d periods %.4g m (model %.4g), periods %d-%d %.4g m (model %.4g)\n",
      axis, direction, kTransient, x_transient - x0, model[kTransient] - model[0], kTransient, kPeriods,
      steady, model_steady);
  EXPECT_GT(steady * direction, 0.0);
  EXPECT_NEAR(steady, model_steady, 0.15 * std::abs(model_steady));
  // Holding where it stopped: once the position loop took over (0.2 s), it stays.
  rig.platform->run(0.2);
  const double held = sim.true_position_m();
  rig.platform->run(0.3);
  EXPECT_NEAR(sim.true_position_m(), held, 20e-9);
  for (int other = 0; other < 3; ++other) {
    if (other != axis) {
      EXPECT_NEAR(rig.platform->simulation().axes[static_cast<std::size_t>(other)]->true_position_m(), 0.0,
                  50e-9);
    }
  }
  if (axis != 3) {
    EXPECT_NEAR(sims.rotary->true_position_m(), 0.0, 50e-9);  // nor did the rotor turn
  }
}

TEST(OpenLoop, PeriodsUpStepWhatTheModelStepsAndEndHolding) { expect_steps_like_the_model(0, +1); }
TEST(OpenLoop, PeriodsDownStepWhatTheModelStepsAndEndHolding) { expect_steps_like_the_model(1, -1); }
TEST(OpenLoop, TheRotaryAxisStepsTheModelsArcAndEndsHolding) {
  expect_steps_like_the_model(3, +1);
  expect_steps_like_the_model(3, -1);
}

TEST(OpenLoop, SteppingTheRotaryAxisStopsAtTheEndOfItsTravel) {
  SteppingRig rig;
  platform::Platform& p = *rig.platform;
  ASSERT_TRUE(p.start_open_loop_steps(3, 100.0, 4000.0, +1, 1'000'000));  // far past +62 deg
  for (int i = 0; i < 1000 && p.open_loop_running(3); ++i) p.run(0.05);
  EXPECT_FALSE(p.open_loop_running(3)) << "stopped at the travel's end, long before its periods";
  const double stopped = p.yaw_rad();
  std::printf("rotary stopped at %.6f rad (travel %.6f rad)\n", stopped, p.yaw_max_rad());
  // At the travel's end: the run stops there, the loop then holds the target clamped to it.
  EXPECT_NEAR(stopped, p.yaw_max_rad(), 1e-3);
  p.run(0.3);
  EXPECT_NEAR(p.yaw_rad(), stopped, 1e-5);  // holding
}

TEST(OpenLoop, NothingStepsWithoutTheDeadmanAndReleasingItStopsAtOnce) {
  SteppingRig rig;
  rig.in.deadman = false;
  rig.platform->set_console_input(rig.in);
  EXPECT_FALSE(rig.platform->start_open_loop_steps(0, 40.0, 500.0, +1, 100));
  rig.in.deadman = true;
  rig.platform->set_console_input(rig.in);
  ASSERT_TRUE(rig.platform->start_open_loop_steps(0, 40.0, 500.0, +1, 1000));
  rig.platform->run(0.05);
  rig.in.deadman = false;  // released mid-run
  rig.platform->run(0.002);
  EXPECT_FALSE(rig.platform->open_loop_running(0));
  const double stopped = rig.true_x();
  rig.platform->run(0.2);
  EXPECT_NEAR(rig.true_x(), stopped, 100e-9);
}

TEST(OpenLoop, AFaultHaltsTheRunAndRefusesNewOnes) {
  SteppingRig rig;
  ASSERT_TRUE(rig.platform->start_open_loop_steps(2, 40.0, 500.0, +1, 1000));
  rig.platform->run(0.02);
  rig.platform->fault_all();
  EXPECT_FALSE(rig.platform->open_loop_running(2));
  EXPECT_FALSE(rig.platform->start_open_loop_steps(2, 40.0, 500.0, +1, 10));
}

TEST(OpenLoop, SteppingDownStopsAtTheFloorWhateverTheCountAsked) {
  SteppingRig rig;
  const double floor_tip_m = rig.config.world.min_tip_height_m;
  ASSERT_GT(rig.platform->simulation().gripper->tip_position_m().z(), floor_tip_m + 100e-6);
  ASSERT_TRUE(rig.platform->start_open_loop_steps(2, 100.0, 2000.0, -1, 1'000'000));  // far below the floor
  for (int i = 0; i < 200 && rig.platform->open_loop_running(2); ++i) rig.platform->run(0.05);
  EXPECT_FALSE(rig.platform->open_loop_running(2)) << "stopped by the floor, long before its periods";
  const double stopped = rig.platform->simulation().gripper->tip_position_m().z();
  std::printf("stopped at tip height %.3g m (floor %.3g m)\n", stopped, floor_tip_m);
  EXPECT_GT(stopped, floor_tip_m - 1e-6);  // at most a tick's stepping past it
  rig.platform->run(0.3);
  EXPECT_NEAR(rig.platform->simulation().gripper->tip_position_m().z(), stopped, 0.5e-6);  // holding
}

TEST(OpenLoop, OutOfRangeDrivesAreRefused) {
  SteppingRig rig;
  EXPECT_FALSE(rig.platform->start_open_loop_steps(4, 40.0, 500.0, +1, 10));
  EXPECT_FALSE(rig.platform->start_open_loop_steps(-1, 40.0, 500.0, +1, 10));
  EXPECT_FALSE(rig.platform->start_open_loop_steps(3, 150.0, 500.0, +1, 10));
  EXPECT_FALSE(rig.platform->start_open_loop_steps(0, 150.0, 500.0, +1, 10));
  EXPECT_FALSE(rig.platform->start_open_loop_steps(0, 40.0, 0.0, +1, 10));
  EXPECT_FALSE(rig.platform->start_open_loop_steps(0, 40.0, 500.0, +1, 0));
  EXPECT_FALSE(
      rig.platform->start_open_loop_steps(0, std::numeric_limits<double>::quiet_NaN(), 500.0, +1, 10));
}

TEST(OpenLoop, WithoutTheRotaryAxisAxis3IsRefused) {
  platform::PlatformConfig config;
  config.stage.rotary.enabled = false;
  platform::Platform p(config);
  teleop::ConsoleInput in;
  in.active = in.fresh = in.deadman = true;
  p.set_console_input(in);
  EXPECT_FALSE(p.start_open_loop_steps(3, 40.0, 500.0, +1, 10));
  EXPECT_TRUE(p.start_open_loop_steps(2, 40.0, 500.0, +1, 10));
}

}  // namespace
}  // namespace mc::devices
