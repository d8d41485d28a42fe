// The skeleton of a hardware driver (docs/hardware.md): a SlaveAxis over a register bus. The
// "hardware" behind the fake bus is the stick-slip model, so the driver is exercised in closed
// loop with the platform's StageController exactly as a real axis would be, and the test shows
// what a driver must guarantee: the lifecycle, a real-time-safe update(), the safe state on a
// bus fault.

#include <gtest/gtest.h>

#include <array>
#include <thread>

#include "microcobot/core/error.h"
#include "microcobot/motion/step_map.h"
#include "microcobot/platform/platform.h"
#include "microcobot/platform/stage_controller.h"
#include "platform/skeleton_drivers.h"
#include "support/counting_allocator.h"

namespace mc::platform {
namespace {

using test::FakeBus;
using test::SkeletonAxisDriver;
using test::SkeletonBench;

TEST(HardwareDriver, ASkeletonAxisDriverRunsTheStageControllerInClosedLoop) {
  const stickslip::ActuatorModel model{stickslip::StickSlipParams{}};
  const motion::StepMap map(model);
  motion::PositionControlParams cp;
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
  EXPECT_EQ(axis.state(), devices::Lifecycle::kFault);
  EXPECT_FALSE(bus.powered);
  EXPECT_EQ(bus.fifo_size, 0);
}

TEST(HardwareDriver, ThePlatformRunsOnDriversHandedToIt) {
  // The whole platform (watchdogs, coupling, stage controller, telemetry) on drivers instead of
  // the simulation: moving the handle 1 mm moves the X axis by the motion scale (10 um) through
  // the skeleton driver's registers.
  PlatformConfig config;
  SkeletonBench bench(config);
  auto& buses = bench.buses;
  Platform p(config, bench.devices());
  auto& hand = *bench.hand;
  auto& grip = *bench.gripper;
  EXPECT_FALSE(p.simulated());
  EXPECT_THROW(p.simulation(), InvalidParams);
  for (const auto& b : buses) EXPECT_TRUE(b.powered);  // configured and activated
  p.loop().run_for(1000);
  ASSERT_TRUE(p.teleop().engaged);
  const double x0 = p.axis(0).position_m();
  hand.handle_m.x = 1e-3;
  std::size_t allocations = 0;
  {
    // The loop's thread (run_for runs it here); threads of the process beside it do not count.
    test::AllocationGuard guard(std::this_thread::get_id());
    p.loop().run_for(5000);  // 0.5 s
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_NEAR(p.axis(0).position_m() - x0, config.teleop.motion_scale * 1e-3, 20e-9);
  EXPECT_NEAR(p.axis(1).position_m(), buses[1].model->slider_position(buses[1].state), 0.1e-9);
  EXPECT_NEAR(grip.commanded_m, config.teleop.grip_position_scale * 4e-3, 1e-12);  // TéléTweez -> gripper

  // The recording holds the loop's channels only (no ground truth on hardware).
  p.run(0.01);
  EXPECT_EQ(p.recording().channels(), loop_channel_count());
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
  EXPECT_EQ(p.haptic().state(), devices::Lifecycle::kFault);
  EXPECT_DOUBLE_EQ(hand.force_N.x, 0.0);
}

TEST(HardwareDriver, ASimulatedGripperRidesTheDriversStageWhereItsSensorsSayItIs) {
  // Hardware in the loop (devices.gripper: simulated): the microworld and its gripper are this
  // process's, carried by the driver's axes; the driver set's own gripper is not used.
  PlatformConfig config;
  config.devices.gripper = "simulated";
  SkeletonBench bench(config);
  Platform p(config, bench.devices());
  EXPECT_FALSE(p.simulated());
  ASSERT_NE(p.simulated_gripper(), nullptr);
  EXPECT_EQ(&p.gripper(), p.simulated_gripper());
  auto& hand = *bench.hand;
  p.loop().run_for(1000);
  hand.handle_m.x = 1e-3;
  p.loop().run_for(5000);
  const Eigen::Vector3d tip = p.simulated_gripper()->tip_position_m();
  const auto& s = config.stage;
  EXPECT_NEAR(tip.x(), s.home_x_m + p.axis(0).position_m(), 1e-12);
  EXPECT_NEAR(tip.z(), s.home_z_m + p.axis(2).position_m(), 1e-12);
  EXPECT_GT(p.axis(0).position_m(), 5e-6);  // the handle moved the stage, and the tips with it
  // The TéléTweez closes this gripper, not the driver set's.
  EXPECT_NEAR(p.gripper().opening_m(), config.teleop.grip_position_scale * 4e-3, 2e-6);
  EXPECT_DOUBLE_EQ(bench.gripper_log.commanded_m, 0.0);
  EXPECT_TRUE(bench.gripper_log.destroyed) << "the unused driver is released, not kept half-configured";
  // Without simulated masters there is no operator's hand to record: the loop's channels.
  p.run(0.01);
  EXPECT_EQ(p.recording().channels(), loop_channel_count());

  config.devices.gripper = "claw";
  EXPECT_THROW(config.validate(), Error);
  config.devices.gripper = "simulated";
  config.devices.driver = "lab-bench";
  config.microworld = "optical-trap";
  try {
    config.validate();
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("devices.gripper"), std::string::npos) << e.what();
  }
}

TEST(HardwareDriver, APlatformRefusesMissingOrAlreadyConfiguredDevices) {
  PlatformConfig config;
  devices::DeviceSet none;
  try {
    Platform p(config, std::move(none));
    FAIL();
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("devices.axes[0]"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mc::platform
