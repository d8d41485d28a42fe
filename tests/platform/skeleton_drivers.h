#pragma once
/// @file
/// The skeleton of a hardware driver set (docs/hardware.md) for the tests: a `SlaveAxis` over a
/// register bus whose "hardware" is the stick-slip model, and masters and a gripper as a driver
/// would present them, the test playing their hardware (it sets the encoders, reads the commands).

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>

#include "microcobot/devices/device.h"
#include "microcobot/platform/platform.h"
#include "microcobot/stickslip/actuator.h"

namespace mc::test {

using devices::DeviceSet;
using devices::DriveBlock;
using devices::Gripper;
using devices::HapticMaster;
using devices::SlaveAxis;
using devices::TweezersMaster;
using devices::Vec2;
using devices::Vec3;
using platform::PlatformConfig;

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

/// What the fake gripper was asked, kept by the bench (the platform may drop the driver).
struct FakeGripperLog {
  double commanded_m = 0.0;  ///< the last opening commanded while active
  bool destroyed = false;
};

class FakeGripperDriver final : public Gripper {
 public:
  explicit FakeGripperDriver(FakeGripperLog* log = nullptr) : Gripper("fake_gripper"), log_(log) {}
  ~FakeGripperDriver() override {
    if (log_) log_->destroyed = true;
  }
  double commanded_m = 0.0;
  void command_opening_m(double opening) noexcept override {
    if (!active()) return;
    commanded_m = opening;
    if (log_) log_->commanded_m = opening;
  }
  double opening_m() const override { return commanded_m; }
  double grip_force_N() const override { return 0.0; }
  Vec3 contact_force_N() const override { return {}; }
  void update(double) noexcept override {}
  void enter_safe_state() noexcept override {}

 private:
  FakeGripperLog* log_;
};

/// A bench of skeleton drivers: three axes on their buses (the model behind them), fake masters
/// and gripper. `devices()` hands them over once, unconfigured; the bench keeps the buses and
/// pointers to the fakes, so it must outlive the platform.
struct SkeletonBench {
  explicit SkeletonBench(const PlatformConfig& config) : model(platform::axis_params(config)) {
    for (FakeBus& b : buses) {
      b.model = &model;
      b.state = model.initial_state();
    }
  }
  devices::DeviceSet devices() {
    devices::DeviceSet d;
    for (std::size_t i = 0; i < 3; ++i) d.axes[i] = std::make_unique<SkeletonAxisDriver>(buses[i]);
    auto h = std::make_unique<FakeHapticDriver>();
    hand = h.get();
    d.haptic = std::move(h);
    d.tweezers = std::make_unique<FakeTweezersDriver>();
    auto g = std::make_unique<FakeGripperDriver>(&gripper_log);
    gripper = g.get();
    d.gripper = std::move(g);
    return d;
  }
  const stickslip::ActuatorModel model;
  std::array<FakeBus, 3> buses;
  FakeHapticDriver* hand = nullptr;
  FakeGripperDriver* gripper = nullptr;  ///< valid while the platform keeps it
  FakeGripperLog gripper_log;
};

}  // namespace mc::test
