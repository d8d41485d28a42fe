#pragma once
/// @file
/// The device set: every device the loop drives, by its interface (device.h), and the simulated
/// ones by their concrete types. The platform fills it from the configuration (the simulated
/// devices: platform/simulated_device_set.h; or a registered driver's: platform/driver_registry.h);
/// a driver needs nothing above this layer to build one.

#include <array>
#include <memory>

#include "microcobot/devices/camera_device.h"
#include "microcobot/devices/device.h"
#include "microcobot/devices/parallel_positioner.h"
#include "microcobot/devices/simulated_gripper.h"
#include "microcobot/devices/simulated_haptic_master.h"
#include "microcobot/devices/simulated_optical_tweezers.h"
#include "microcobot/devices/simulated_parallel_positioner.h"
#include "microcobot/devices/simulated_slave_axis.h"
#include "microcobot/devices/simulated_tweezers_master.h"

namespace mc::devices {

/// The devices the loop drives, by their interfaces (device.h). A hardware set-up fills it
/// with its drivers (docs/hardware.md); the default platform builds the simulated ones.
struct DeviceSet {
  std::array<std::unique_ptr<SlaveAxis>, 3> axes;  ///< X, Y, Z of the slave stage
  /// The rotary axis under the gripper (optional; motion/rotary_axis.h): a stick-slip axis whose
  /// position is the rotor's arc at stage.rotary.radius_m, driven like the others.
  std::unique_ptr<SlaveAxis> rotary;
  std::unique_ptr<Gripper> gripper;
  std::unique_ptr<HapticMaster> haptic;
  std::unique_ptr<TweezersMaster> tweezers;
  /// The microscope camera and its focus drive (optional: absent, the platform builds the ones
  /// `camera` and `devices.camera` ask for; none when devices.camera.driver is "none").
  std::unique_ptr<Camera> camera;
  std::unique_ptr<FocusDrive> focus;
  /// The 6-DOF parallel positioner carrying the part (optional: `positioner: parallel`, the
  /// thesis's assembly; absent, the platform builds the simulated one the configuration asks for).
  std::unique_ptr<ParallelPositioner> positioner;
};

/// The simulated devices of a platform, by their concrete types (non-owning; null for a driver's
/// device): the scripted operator moves their hands, the session report reads their ground truth.
struct SimulatedDevices {
  std::array<SimulatedSlaveAxis*, 3> axes{};
  SimulatedSlaveAxis* rotary = nullptr;
  SimulatedGripper* gripper = nullptr;  ///< the pick-and-place's (null in the optical-trap scene)
  SimulatedOpticalTweezers* optical_tweezers = nullptr;  ///< the optical-trap scene's (else null)
  SimulatedHapticMaster* haptic = nullptr;
  SimulatedTweezersMaster* tweezers = nullptr;
  SimulatedParallelPositioner* positioner = nullptr;  ///< `positioner: parallel` (else null)
};

}  // namespace mc::devices
