// The skeleton of a hardware driver (docs/hardware.md): a SlaveAxis over a register bus. The
// "hardware" behind the fake bus is the stick-slip model, so the driver is exercised in closed
// loop with the platform's StageController exactly as a real axis would be, and the test shows
// what a driver must guarantee: the lifecycle, a real-time-safe update(), the safe state on a
// bus fault.

#include <gtest/gtest.h>

#include <array>

#include "microcobot/control/step_map.h"
#include "microcobot/core/error.h"
#include "microcobot/platform/platform.h"
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
    bus_.fifo_size = std::min(b.count, FakeBus::kFifo);
    for (int i = 0; i < bus_.fifo_size; ++i)
      bus_.dac_fifo[static_cast<std::size_t>(i)] = std::clamp(b.segments[i].end_V, 0.0, 100.0);
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

// Masters and a gripper as a driver would present them: the test plays the hardware (sets the
// encoders, reads the commands).
class FakeHapticDriver final : public HapticMaster {
 public:
  FakeHapticDriver() : HapticMaster("fake_haptic") {}
  Vec2 handle_m{};       ///< what the Pantograph's encoders read
  bool stalled = false;  ///< the bus stopped delivering readings
  Vec2 force_N{};        ///< the last force sent to the amplifiers
  Vec2 handle_position_m() const override { return handle_m; }
  bool enabled() const override { return true; }
  bool clutch() const override { return false; }
  double jog_m_s() const override { return 0.0; }
  std::uint64_t reading_count() const override { return readings_; }
  void command_force_N(Vec2 force) noexcept override {
    if (active()) force_N = force;
  }
  void update(double) noexcept override {
    if (!stalled) ++readings_;
  }
  void enter_safe_state() noexcept override { force_N = {}; }

 private:
  std::uint64_t readings_ = 0;
};

class FakeTweezersDriver final : public TweezersMaster {
 public:
  FakeTweezersDriver() : TweezersMaster("fake_tweezers") {}
  double opening_m() const override { return 4e-3; }
  std::uint64_t reading_count() const override { return readings_; }
  void command_grip_force_N(double) noexcept override {}
  void update(double) noexcept override { ++readings_; }
  void enter_safe_state() noexcept override {}

 private:
  std::uint64_t readings_ = 0;
};

class FakeGripperDriver final : public Gripper {
 public:
  FakeGripperDriver() : Gripper("fake_gripper") {}
  double commanded_m = 0.0;
  void command_opening_m(double opening) noexcept override {
    if (active()) commanded_m = opening;
  }
  double opening_m() const override { return commanded_m; }
  double grip_force_N() const override { return 0.0; }
  Vec3 contact_force_N() const override { return {}; }
  void update(double) noexcept override {}
  void enter_safe_state() noexcept override {}
};

TEST(HardwareDriver, ThePlatformRunsOnDriversHandedToIt) {
  // The whole platform (watchdogs, coupling, stage controller, telemetry) on drivers instead of
  // the simulation: moving the handle 1 mm moves the X axis by the motion scale (10 um) through
  // the skeleton driver's registers.
  PlatformConfig config;
  const stickslip::ActuatorModel model{axis_params(config)};
  std::array<FakeBus, 3> buses;
  PlatformDevices devices;
  for (std::size_t i = 0; i < 3; ++i) {
    buses[i].model = &model;
    buses[i].state = model.initial_state();
    devices.axes[i] = std::make_unique<SkeletonAxisDriver>(buses[i]);
  }
  auto haptic = std::make_unique<FakeHapticDriver>();
  FakeHapticDriver& hand = *haptic;
  devices.haptic = std::move(haptic);
  devices.tweezers = std::make_unique<FakeTweezersDriver>();
  auto gripper = std::make_unique<FakeGripperDriver>();
  FakeGripperDriver& grip = *gripper;
  devices.gripper = std::move(gripper);

  Platform p(config, std::move(devices));
  EXPECT_FALSE(p.simulated());
  EXPECT_THROW(p.simulation(), InvalidParams);
  for (const auto& b : buses) EXPECT_TRUE(b.powered);  // configured and activated
  p.loop().run_for(1000);
  ASSERT_TRUE(p.teleop().engaged);
  const double x0 = p.axis(0).position_m();
  hand.handle_m.x = 1e-3;
  std::size_t allocations = 0;
  {
    test::AllocationGuard guard;
    p.loop().run_for(5000);  // 0.5 s
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_NEAR(p.axis(0).position_m() - x0, config.teleop.motion_scale * 1e-3, 20e-9);
  EXPECT_NEAR(p.axis(1).position_m(), buses[1].model->slider_position(buses[1].state), 0.1e-9);
  EXPECT_NEAR(grip.commanded_m, config.teleop.grip_position_scale * 4e-3, 1e-12);  // TéléTweez -> gripper

  // The recording holds the loop's channels only (no ground truth on hardware).
  p.run(0.01);
  EXPECT_EQ(p.recording().channels(), kLoopChannelCount);
  EXPECT_GT(p.recording().size(), 0u);

  // A stalled haptic bus: the watchdog holds the slave; a driver fault: every device safe.
  hand.stalled = true;
  p.loop().run_for(static_cast<std::uint64_t>(config.loop.watchdog_ticks) + 2);
  EXPECT_TRUE(p.teleop().stale);
  EXPECT_FALSE(p.teleop().engaged);
  buses[2].fault = true;
  p.loop().run_for(1);
  EXPECT_TRUE(p.faulted());
  for (const auto& b : buses) EXPECT_FALSE(b.powered);
  EXPECT_EQ(p.haptic().state(), Lifecycle::kFault);
  EXPECT_DOUBLE_EQ(hand.force_N.x, 0.0);
}

TEST(HardwareDriver, APlatformRefusesMissingOrAlreadyConfiguredDevices) {
  PlatformConfig config;
  PlatformDevices none;
  try {
    Platform p(config, std::move(none));
    FAIL();
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("devices.axes[0]"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mc::platform
