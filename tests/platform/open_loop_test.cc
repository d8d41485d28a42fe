// Issue #30: open-loop stepping on the platform (the ANC300's stepu/stepd): n sawtooth periods
// through the stick-slip model move the axis what the model alone moves for the same drive, end
// holding, and obey the safety rules (deadman, fault, e-stop).

#include <gtest/gtest.h>

#include <cmath>

#include "microcobot/platform/platform.h"
#include "microcobot/stickslip/actuator.h"
#include "microcobot/stickslip/drive.h"

namespace mc::platform {
namespace {

struct SteppingRig {
  PlatformConfig config;
  std::unique_ptr<Platform> platform;
  control::ConsoleInput in;
  SteppingRig() {
    platform = std::make_unique<Platform>(config);
    in.active = true;
    in.fresh = true;
    in.deadman = true;
    platform->set_operator([this](const TickInfo&) { platform->set_console_input(in); });
    platform->set_console_input(in);
    platform->run(0.05);  // settled in hold
  }
  double true_x() const { return platform->simulation().axes[0]->true_position_m(); }
};

// What the model alone moves for `periods` periods of the sawtooth, as `stickslip simulate` runs
// it from rest, without its first period: that one holds the power-up transient (the hysteresis'
// initial loading, the contact's first strain) that an axis which has been holding does not go
// through. Returns the steady displacement per period times `periods`.
double model_steady_displacement(const PlatformConfig& config, double amplitude_V, double frequency_Hz,
                                 stickslip::Direction dir, int periods) {
  const stickslip::ActuatorModel m(axis_params(config));
  const auto w = stickslip::make_waveform(stickslip::WaveKind::kSawtooth, amplitude_V, frequency_Hz, dir,
                                          m.params().drive);
  stickslip::ActuatorState s = m.initial_state();
  double x = 0.0, x_first = 0.0;
  const double first_end = 1.0 / frequency_Hz;
  stickslip::simulate_each(m, w, periods / frequency_Hz, 1, s, [&](const stickslip::ActuatorState& st) {
    x = m.slider_position(st);
    if (st.t_s <= first_end) x_first = x;
  });
  return (x - x_first) * periods / (periods - 1);
}

constexpr double kAmplitude_V = 60.0, kFrequency_Hz = 500.0;
constexpr int kPeriods = 100;
constexpr double kRelativeTolerance = 0.10;

TEST(OpenLoop, NPeriodsUpMoveWhatTheModelMovesAndEndHolding) {
  SteppingRig rig;
  const double x0 = rig.true_x();
  ASSERT_TRUE(rig.platform->start_open_loop_steps(0, kAmplitude_V, kFrequency_Hz, +1, kPeriods));
  EXPECT_TRUE(rig.platform->open_loop_running(0));
  rig.platform->run(kPeriods / kFrequency_Hz + 0.005);
  EXPECT_FALSE(rig.platform->open_loop_running(0));
  const double moved = rig.true_x() - x0;
  const double model = model_steady_displacement(rig.config, kAmplitude_V, kFrequency_Hz,
                                                 stickslip::Direction::kForward, kPeriods);
  std::printf("open loop up: moved %.4g m, model %.4g m\n", moved, model);
  EXPECT_GT(moved, 0.0);
  EXPECT_NEAR(moved, model, kRelativeTolerance * std::abs(model));
  // Holding: the target where the axis ended, and it stays there.
  const double end = rig.true_x();
  rig.platform->run(0.2);
  EXPECT_NEAR(rig.true_x(), end, 50e-9);
}

TEST(OpenLoop, StepsDownMoveBackward) {
  SteppingRig rig;
  const double x0 = rig.true_x();
  const double y0 = rig.platform->simulation().axes[1]->true_position_m();
  ASSERT_TRUE(rig.platform->start_open_loop_steps(1, kAmplitude_V, kFrequency_Hz, -1, kPeriods));
  rig.platform->run(kPeriods / kFrequency_Hz + 0.005);
  const double moved = rig.platform->simulation().axes[1]->true_position_m() - y0;
  const double model = model_steady_displacement(rig.config, kAmplitude_V, kFrequency_Hz,
                                                 stickslip::Direction::kBackward, kPeriods);
  std::printf("open loop down: moved %.4g m, model %.4g m\n", moved, model);
  EXPECT_LT(moved, 0.0);
  EXPECT_NEAR(moved, model, kRelativeTolerance * std::abs(model));
  EXPECT_NEAR(rig.true_x(), x0, 50e-9);  // the other axes held
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

TEST(OpenLoop, OutOfRangeDrivesAreRefused) {
  SteppingRig rig;
  EXPECT_FALSE(rig.platform->start_open_loop_steps(3, 40.0, 500.0, +1, 10));
  EXPECT_FALSE(rig.platform->start_open_loop_steps(0, 150.0, 500.0, +1, 10));
  EXPECT_FALSE(rig.platform->start_open_loop_steps(0, 40.0, 0.0, +1, 10));
  EXPECT_FALSE(rig.platform->start_open_loop_steps(0, 40.0, 500.0, +1, 0));
  EXPECT_FALSE(rig.platform->start_open_loop_steps(0, NAN, 500.0, +1, 10));
}

}  // namespace
}  // namespace mc::platform
