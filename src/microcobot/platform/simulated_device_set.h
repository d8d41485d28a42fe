#pragma once
/// @file
/// The device set of the simulated platform, built from the configuration: the X, Y, Z stick-slip
/// axes (each with its own sensor noise), the rotary axis under the gripper, the pick-and-place
/// gripper or the optical-trap scene's tweezers, the dual-stage haptic master and the TéléTweez.
/// A driver's device set comes from its registered factory instead (driver_registry.h); the
/// simulated gripper may still stand under a driver's stage (hardware in the loop).
///
/// The devices refer to the platform's stick-slip model and microworld, which the platform owns
/// and which must outlive them.

#include "microcobot/devices/device_set.h"
#include "microcobot/microworld/pick_place_world.h"
#include "microcobot/platform/platform_config.h"
#include "microcobot/stickslip/actuator.h"

namespace mc::platform {

/// A device set and its simulated devices by their concrete types (non-owning views into it).
struct SimulatedDeviceSet {
  devices::DeviceSet devices;
  devices::SimulatedDevices simulation;
};

/// The simulated device set of `config` (devices.driver "simulated") over `model` and `world`,
/// the tool's home at `home_m` (world coordinates).
SimulatedDeviceSet build_simulated_devices(const PlatformConfig& config,
                                           const stickslip::ActuatorModel& model,
                                           microworld::PickPlaceWorld& world, const Eigen::Vector3d& home_m);

/// Hardware in the loop (devices.gripper "simulated"): the microworld's gripper under the stage of
/// a driver's set, its finger tips where the driver's axes say the stage is. Replaces the set's
/// gripper and records it in `simulation`. Throws InvalidParams naming the key when the scene is
/// not the pick-and-place or an axis is missing.
void add_simulated_gripper(const PlatformConfig& config, microworld::PickPlaceWorld& world,
                           const Eigen::Vector3d& home_m, devices::DeviceSet& set,
                           devices::SimulatedDevices& simulation);

}  // namespace mc::platform
