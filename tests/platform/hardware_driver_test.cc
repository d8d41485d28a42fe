// The skeleton of a hardware driver (docs/hardware.md): a SlaveAxis over a register bus. The
// "hardware" behind the fake bus is the stick-slip model, so the driver is exercised in closed
// loop with the platform's StageController exactly as a real axis would be, and the test shows
// what a driver must guarantee: the lifecycle, a real-time-safe update(), the safe state on a
// bus fault.

#include <gtest/gtest.h>

#include <array>

#include "microcobot/control/step_map.h"
#include "microcobot/platform/stage_controller.h"
#include "support/counting_allocator.h"

namespace mc::platform {
namespace {

// What an amplifier + encoder board exposes: a DAC FIFO, an encoder counter, a fault flag.
struct FakeBus {
  static constexpr int kFifo = 16;
  std::array<double, kFifo> dac_fifo{};
  int fifo_size = 0;
  long long encoder_counts = 0;  ///< 0.1 nm per count
  bool fault = false;
  bool powered = false;
  // The board plays its FIFO at 100 kHz into the actuator (here: the model).
  const stickslip::ActuatorModel* model = nullptr;
  stickslip::ActuatorState state;
  void clock(int samples) {
    for (int i = 0; i < samples; ++i) {
      const double u =
          powered && fifo_size > 0 ? dac_fifo[static_cast<std::size_t>(std::min(i, fifo_size - 1))] : 0.0;
      model->step(state, u);
    }
    fifo_size = 0;
    encoder_counts = std::llround(model->slider_position(state) / 0.1e-9);
  }
};

class SkeletonAxisDriver final : public SlaveAxis {
 public:
  explicit SkeletonAxisDriver(FakeBus& bus) : SlaveAxis("skeleton"), bus_(bus) {}
  double sample_period_s() const override { return 1e-5; }
  double max_voltage_V() const override { return 100.0; }
  void command_drive(const DriveBlock& b) noexcept override {
    if (!active()) return;
    // Copy into the FIFO (no allocation), clamped to the amplifier's range.
    bus_.fifo_size = std::min(b.samples, FakeBus::kFifo);
    for (int i = 0; i < bus_.fifo_size; ++i)
      bus_.dac_fifo[static_cast<std::size_t>(i)] = std::clamp(b.volts[i], 0.0, 100.0);
  }
  double position_m() const override { return static_cast<double>(bus_.encoder_counts) * 0.1e-9; }
  bool at_end_stop() const override { return false; }
  void update(double dt_s) noexcept override {
    bus_.clock(static_cast<int>(std::lround(dt_s / sample_period_s())));
    if (bus_.fault) fault();
  }
  void enter_safe_state() noexcept override {
    bus_.fifo_size = 0;  // the board holds 0 V with an empty FIFO
    bus_.powered = false;
  }

 protected:
  void on_configure() override { bus_.powered = false; }
  void on_activate() override { bus_.powered = true; }

 private:
  FakeBus& bus_;
};

TEST(HardwareDriver, ASkeletonAxisDriverRunsTheStageControllerInClosedLoop) {
  const stickslip::ActuatorModel model{stickslip::StickSlipParams{}};
  const control::StepMap map(model);
  control::PositionControlParams cp;
  cp.control_rate_Hz = 1000.0;
  StageController ctrl(cp, model.params(), map, 10, 1e-5);
  FakeBus bus;
  bus.model = &model;
  bus.state = model.initial_state();
  SkeletonAxisDriver axis(bus);
  axis.configure();
  axis.activate();
  const Eigen::Vector3d target(20e-6, 0, 0);
  std::size_t allocations = 0;
  {
    test::AllocationGuard guard;
    for (int tick = 0; tick < 5000; ++tick) {  // 0.5 s of a 10 kHz loop
      if (tick % 10 == 0) ctrl.update(target, Eigen::Vector3d::Zero(), {axis.position_m(), 0.0, 0.0});
      axis.command_drive(ctrl.drive(0));
      axis.update(1e-4);
    }
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_NEAR(axis.position_m(), 20e-6, 10e-9);  // positioned through the driver's registers
  bus.fault = true;  // the board reports a fault: the driver goes to its safe state
  axis.command_drive(ctrl.drive(0));
  axis.update(1e-4);
  EXPECT_EQ(axis.state(), Lifecycle::kFault);
  EXPECT_FALSE(bus.powered);
  EXPECT_EQ(bus.fifo_size, 0);
}

}  // namespace
}  // namespace mc::platform
