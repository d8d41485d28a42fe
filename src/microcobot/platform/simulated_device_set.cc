#include "microcobot/platform/simulated_device_set.h"

#include <array>
#include <memory>
#include <string>

#include "microcobot/core/error.h"

namespace mc::platform {
namespace {

// The gripper of the pick-and-place microworld carried by `axes`, turned by the rotary axis when
// there is one.
std::unique_ptr<devices::SimulatedGripper> make_gripper(const PlatformConfig& config,
                                                        microworld::PickPlaceWorld& world,
                                                        const std::array<const devices::SlaveAxis*, 3>& axes,
                                                        const devices::SlaveAxis* rotary,
                                                        const Eigen::Vector3d& home_m) {
  auto gripper = std::make_unique<devices::SimulatedGripper>(
      "gripper", world, axes, devices::Vec3{home_m.x(), home_m.y(), home_m.z()});
  if (rotary != nullptr) gripper->set_rotary(rotary, config.stage.rotary);
  return gripper;
}

}  // namespace

SimulatedDeviceSet build_simulated_devices(const PlatformConfig& config,
                                           const stickslip::ActuatorModel& model,
                                           microworld::PickPlaceWorld& world, const Eigen::Vector3d& home_m) {
  SimulatedDeviceSet out;
  devices::DeviceSet& set = out.devices;
  devices::SimulatedDevices& sim = out.simulation;
  const double dt = config.loop.period_s();
  const char* names[3] = {"axis_x", "axis_y", "axis_z"};
  for (std::size_t i = 0; i < 3; ++i) {
    motion::PositionSensorParams sp = config.stage.sensor;
    sp.seed = config.stage.sensor.seed + static_cast<int>(i);  // independent noise per axis
    auto axis = std::make_unique<devices::SimulatedSlaveAxis>(names[i], model, sp, 0.0);
    sim.axes[i] = axis.get();
    set.axes[i] = std::move(axis);
  }
  if (config.stage.rotary.enabled && !config.optical_trap_scene()) {
    motion::PositionSensorParams sp = config.stage.sensor;
    sp.seed = config.stage.sensor.seed + 3;
    auto rotary = std::make_unique<devices::SimulatedSlaveAxis>("axis_theta", model, sp, 0.0);
    sim.rotary = rotary.get();
    set.rotary = std::move(rotary);
  }
  const std::array<const devices::SimulatedSlaveAxis*, 3> carriers{sim.axes[0], sim.axes[1], sim.axes[2]};
  if (config.optical_trap_scene()) {
    auto trap = std::make_unique<devices::SimulatedOpticalTweezers>(
        "optical_tweezers", config.optical_trap, carriers, devices::Vec3{home_m.x(), home_m.y(), home_m.z()},
        dt);
    sim.optical_tweezers = trap.get();
    set.gripper = std::move(trap);
  } else {
    auto gripper =
        make_gripper(config, world, {carriers[0], carriers[1], carriers[2]}, set.rotary.get(), home_m);
    sim.gripper = gripper.get();
    set.gripper = std::move(gripper);
  }
  auto haptic = std::make_unique<devices::SimulatedHapticMaster>(
      "dual_stage", config.haptic.plant, config.haptic.render, config.haptic.pantograph, dt);
  auto tweezers = std::make_unique<devices::SimulatedTweezersMaster>("teletweez", config.tweezers, dt);
  sim.haptic = haptic.get();
  sim.tweezers = tweezers.get();
  set.haptic = std::move(haptic);
  set.tweezers = std::move(tweezers);
  return out;
}

void add_simulated_gripper(const PlatformConfig& config, microworld::PickPlaceWorld& world,
                           const Eigen::Vector3d& home_m, devices::DeviceSet& set,
                           devices::SimulatedDevices& simulation) {
  require(!config.optical_trap_scene(), "devices.gripper", "simulated needs the pick-place microworld");
  for (std::size_t i = 0; i < 3; ++i)
    if (set.axes[i] == nullptr) throw InvalidParams("devices.axes[" + std::to_string(i) + "]", "is missing");
  auto gripper = make_gripper(config, world, {set.axes[0].get(), set.axes[1].get(), set.axes[2].get()},
                              set.rotary.get(), home_m);
  simulation.gripper = gripper.get();
  set.gripper = std::move(gripper);
}

}  // namespace mc::platform
