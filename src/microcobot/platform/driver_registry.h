#pragma once
/// @file
/// Hardware drivers chosen by name from the platform's configuration (docs/hardware.md).
///
/// A lab writes the drivers of its bench (three `SlaveAxis`, a `Gripper`, a `HapticMaster`, a
/// `TweezersMaster`: device.h), registers a factory that builds them under a name, links it into
/// the program (CMake: `MC_DRIVER_SOURCES`), and selects it in the configuration:
///
///     devices: {driver: lab-bench, connection: "192.168.10.5:5000"}
///
/// `microcobot serve --config FILE` then runs the platform on those devices. "simulated" (the
/// default) is the digital twin and is built by `Platform(config)` itself. As ros2_control's
/// hardware plugins, the registry only builds: the platform configures and activates what the
/// factory returns (unconfigured), and its loop reaches the devices through their interfaces.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "microcobot/platform/platform.h"

namespace mc::platform {

/// Builds a bench's devices, unconfigured, from the configuration (`config.devices.connection`
/// says what to open; the loop's period, the axes' sample period and the limits are there too).
/// Throws mc::Error when a device cannot be reached.
using DeviceFactory = std::function<devices::DeviceSet(const PlatformConfig& config)>;

/// Registers `factory` under `name` (letters, digits, '-', '_'; not "simulated"). Throws
/// mc::InvalidParams on a bad or taken name. Thread-safe; meant for static initialisation
/// (DriverRegistration) or the start of main().
void register_devices(const std::string& name, DeviceFactory factory);

/// The names that `devices.driver` accepts: "simulated", then the registered ones, sorted.
std::vector<std::string> device_driver_names();

/// True for "simulated" and every registered name.
bool is_device_driver(const std::string& name);

/// The registered factory's devices for `config.devices.driver` (not "simulated": those are the
/// platform's own). Throws mc::InvalidParams naming `devices.driver` and the known names.
devices::DeviceSet make_driver_devices(const PlatformConfig& config);

/// The platform `config` asks for: simulated, or on the selected driver's devices.
std::unique_ptr<Platform> make_platform(const PlatformConfig& config);

/// Builds a camera's frame source (unopened) from the configuration (`devices.camera.source`
/// says what to open). Throws mc::Error.
using CameraSourceFactory =
    std::function<std::unique_ptr<devices::FrameSource>(const PlatformConfig& config)>;

/// Registers a camera driver under `name` (as register_devices; not "none" or "simulated").
void register_camera(const std::string& name, CameraSourceFactory factory);
/// The names `devices.camera.driver` accepts: "none", "simulated" when this build renders
/// images (vision/), "opencv" when built with OpenCV (MC_WITH_OPENCV), then the registered ones.
std::vector<std::string> camera_driver_names();
bool is_camera_driver(const std::string& name);
/// The frame source `config.devices.camera` selects; null for "none". Throws mc::InvalidParams
/// naming `devices.camera.driver` for an unknown one, mc::Error when the driver cannot be built.
std::unique_ptr<devices::FrameSource> make_camera_source(const PlatformConfig& config);

/// Builds the parallel positioner's device (unconfigured) from the configuration
/// (`parallel_positioner.connection` says what to open; its geometry is there too). Throws mc::Error.
using PositionerFactory =
    std::function<std::unique_ptr<devices::ParallelPositioner>(const PlatformConfig& config)>;

/// Registers a parallel positioner's driver under `name` (as register_devices; not "simulated"),
/// selected by `parallel_positioner.driver` with `positioner: parallel`:
///
///     positioner: parallel
///     parallel_positioner: {driver: pi-hexapod, connection: "192.168.10.7:50000"}
void register_positioner(const std::string& name, PositionerFactory factory);
/// The names `parallel_positioner.driver` accepts: "simulated", then the registered ones, sorted.
std::vector<std::string> positioner_driver_names();
bool is_positioner_driver(const std::string& name);
/// The registered factory's positioner for `config.parallel_positioner.driver` (not "simulated":
/// the platform builds that one). Throws mc::InvalidParams naming `parallel_positioner.driver` and
/// the known names, mc::Error when the driver cannot be built.
std::unique_ptr<devices::ParallelPositioner> make_positioner(const PlatformConfig& config);

/// Registers a driver set at static initialisation, in a source file compiled into the program
/// itself (a static library's object nobody references would be left out by the linker):
///     const mc::platform::DriverRegistration kLabBench{"lab-bench", make_lab_bench};
struct DriverRegistration {
  DriverRegistration(const std::string& name, DeviceFactory factory) {
    register_devices(name, std::move(factory));
  }
};

}  // namespace mc::platform
