#include "microcobot/devices/device.h"

#include <gtest/gtest.h>

#include "microcobot/core/error.h"

namespace mc::devices {
namespace {

// The smallest honest axis: position integrates the commanded voltage.
class FakeAxis : public SlaveAxis {
 public:
  FakeAxis() : SlaveAxis("x") {}
  double sample_period_s() const override { return 1e-4; }
  double max_voltage_V() const override { return 100.0; }
  void command_drive(const DriveBlock& b) noexcept override {
    if (active() && b.count > 0) volts_ = b.segments[b.count - 1].end_V;
  }
  void command_voltage_V(double v) noexcept {
    const stickslip::DriveSegment one[1] = {stickslip::DriveSegment::to(v)};
    command_drive(DriveBlock{one, 1});
  }
  double position_m() const override { return x_; }
  bool at_end_stop() const override { return false; }
  void update(double dt) noexcept override { x_ += 1e-6 * volts_ * dt; }
  void enter_safe_state() noexcept override {
    volts_ = 0.0;
    ++safe_calls;
  }
  double volts() const { return volts_; }
  int safe_calls = 0;
  bool fail_configure = false;

 protected:
  void on_configure() override {
    if (fail_configure) throw InvalidInput("fake axis: no sensor");
  }

 private:
  double volts_ = 0.0;
  double x_ = 0.0;
};

TEST(Device, LifecycleAndCommandsOnlyWhileActive) {
  FakeAxis axis;
  EXPECT_EQ(axis.state(), Lifecycle::kUnconfigured);
  axis.command_voltage_V(50);
  EXPECT_EQ(axis.volts(), 0.0);
  EXPECT_THROW(axis.activate(), InvalidInput);
  axis.configure();
  EXPECT_EQ(axis.state(), Lifecycle::kInactive);
  axis.activate();
  axis.command_voltage_V(50);
  EXPECT_EQ(axis.volts(), 50.0);
  EXPECT_THROW(axis.configure(), InvalidInput);
  axis.deactivate();
  EXPECT_EQ(axis.state(), Lifecycle::kInactive);
  EXPECT_EQ(axis.volts(), 0.0);  // deactivation goes through the safe state
}

TEST(Device, FaultGoesToTheSafeStateAtOnceAndLatches) {
  FakeAxis axis;
  axis.configure();
  axis.activate();
  axis.command_voltage_V(80);
  axis.fault();
  EXPECT_EQ(axis.volts(), 0.0);
  EXPECT_EQ(axis.state(), Lifecycle::kFault);
  EXPECT_THROW(axis.activate(), InvalidInput);
  axis.configure();  // recovery is an explicit reconfiguration
  axis.activate();
  EXPECT_TRUE(axis.active());
}

TEST(Device, FailedConfigurationLeavesTheDeviceInFault) {
  FakeAxis axis;
  axis.fail_configure = true;
  EXPECT_THROW(axis.configure(), InvalidInput);
  EXPECT_EQ(axis.state(), Lifecycle::kFault);
  EXPECT_GE(axis.safe_calls, 1);
}

}  // namespace
}  // namespace mc::devices
