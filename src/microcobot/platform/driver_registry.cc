#include "microcobot/platform/driver_registry.h"

#include <algorithm>
#include <map>
#include <mutex>
#include <utility>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "microcobot/devices/opencv_camera.h"
#include "microcobot/platform/simulated_camera.h"

namespace mc::platform {
namespace {

constexpr const char* kSimulated = "simulated";

// Function-local statics: registrations may run during static initialisation, in any order.
std::map<std::string, DeviceFactory>& entries() {
  static std::map<std::string, DeviceFactory> e;
  return e;
}
std::mutex& entries_mutex() {
  static std::mutex m;
  return m;
}
std::map<std::string, CameraSourceFactory>& cameras() {
  static std::map<std::string, CameraSourceFactory> c;
  return c;
}

std::map<std::string, PositionerFactory>& positioners() {
  static std::map<std::string, PositionerFactory> p;
  return p;
}

constexpr const char* kNoCamera = "none";
constexpr const char* kOpenCv = "opencv";

bool valid_name(const std::string& name) {
  return !name.empty() && name.size() <= 64 && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_';
  });
}

}  // namespace

void register_devices(const std::string& name, DeviceFactory factory) {
  if (!valid_name(name))
    throw InvalidParams("devices.driver",
                        "a driver's name is 1-64 letters, digits, '-' or '_', not '" + excerpt(name) + "'");
  if (name == kSimulated) throw InvalidParams("devices.driver", "'simulated' is the built-in digital twin");
  if (!factory) throw InvalidParams("devices.driver", "'" + name + "' has no factory");
  std::lock_guard lock(entries_mutex());
  if (!entries().emplace(name, std::move(factory)).second)
    throw InvalidParams("devices.driver", "'" + name + "' is registered twice");
}

std::vector<std::string> device_driver_names() {
  std::vector<std::string> names{kSimulated};
  std::lock_guard lock(entries_mutex());
  for (const auto& entry : entries()) names.push_back(entry.first);
  return names;
}

bool is_device_driver(const std::string& name) {
  if (name == kSimulated) return true;
  std::lock_guard lock(entries_mutex());
  return entries().count(name) > 0;
}

devices::DeviceSet make_driver_devices(const PlatformConfig& config) {
  DeviceFactory factory;
  {
    std::lock_guard lock(entries_mutex());
    const auto it = entries().find(config.devices.driver);
    if (it != entries().end()) factory = it->second;
  }
  if (!factory) {
    config.validate();  // names the key and the known drivers
    throw InvalidParams("devices.driver", "'simulated' is built by the platform itself");
  }
  return factory(config);
}

void register_camera(const std::string& name, CameraSourceFactory factory) {
  if (!valid_name(name))
    throw InvalidParams("devices.camera.driver",
                        "a driver's name is 1-64 letters, digits, '-' or '_', not '" + excerpt(name) + "'");
  if (name == kNoCamera || name == kSimulated || name == kOpenCv)
    throw InvalidParams("devices.camera.driver", "'" + name + "' is built in");
  if (!factory) throw InvalidParams("devices.camera.driver", "'" + name + "' has no factory");
  std::lock_guard lock(entries_mutex());
  if (!cameras().emplace(name, std::move(factory)).second)
    throw InvalidParams("devices.camera.driver", "'" + name + "' is registered twice");
}

std::vector<std::string> camera_driver_names() {
  std::vector<std::string> names{kNoCamera, kSimulated};
  if (devices::opencv_camera_available()) names.emplace_back(kOpenCv);
  std::lock_guard lock(entries_mutex());
  for (const auto& entry : cameras()) names.push_back(entry.first);
  return names;
}

bool is_camera_driver(const std::string& name) {
  const auto names = camera_driver_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

std::unique_ptr<devices::FrameSource> make_camera_source(const PlatformConfig& config) {
  const std::string& name = config.devices.camera.driver;
  if (name == kNoCamera) return nullptr;
  if (name == kSimulated) return make_simulated_camera(config);
  if (name == kOpenCv && devices::opencv_camera_available())
    return devices::make_opencv_camera(config.devices.camera.source);
  CameraSourceFactory factory;
  {
    std::lock_guard lock(entries_mutex());
    const auto it = cameras().find(name);
    if (it != cameras().end()) factory = it->second;
  }
  if (!factory) {
    std::string known;
    for (const std::string& n : camera_driver_names()) known += (known.empty() ? "" : ", ") + n;
    throw InvalidParams(
        "devices.camera.driver",
        "'" + excerpt(name) + "' is not a camera driver of this build (known: " + known + ")");
  }
  return factory(config);
}

void register_positioner(const std::string& name, PositionerFactory factory) {
  if (!valid_name(name))
    throw InvalidParams("parallel_positioner.driver",
                        "a driver's name is 1-64 letters, digits, '-' or '_', not '" + excerpt(name) + "'");
  if (name == kSimulated)
    throw InvalidParams("parallel_positioner.driver", "'simulated' is the built-in positioner");
  if (!factory) throw InvalidParams("parallel_positioner.driver", "'" + name + "' has no factory");
  std::lock_guard lock(entries_mutex());
  if (!positioners().emplace(name, std::move(factory)).second)
    throw InvalidParams("parallel_positioner.driver", "'" + name + "' is registered twice");
}

std::vector<std::string> positioner_driver_names() {
  std::vector<std::string> names{kSimulated};
  std::lock_guard lock(entries_mutex());
  for (const auto& entry : positioners()) names.push_back(entry.first);
  return names;
}

bool is_positioner_driver(const std::string& name) {
  if (name == kSimulated) return true;
  std::lock_guard lock(entries_mutex());
  return positioners().count(name) > 0;
}

std::unique_ptr<devices::ParallelPositioner> make_positioner(const PlatformConfig& config) {
  const std::string& name = config.parallel_positioner.driver;
  PositionerFactory factory;
  {
    std::lock_guard lock(entries_mutex());
    const auto it = positioners().find(name);
    if (it != positioners().end()) factory = it->second;
  }
  if (!factory) {
    std::string known;
    for (const std::string& n : positioner_driver_names()) known += (known.empty() ? "" : ", ") + n;
    throw InvalidParams(
        "parallel_positioner.driver",
        "'" + excerpt(name) + "' is not a registered positioner driver (known: " + known + ")");
  }
  return factory(config);
}

std::unique_ptr<Platform> make_platform(const PlatformConfig& config) {
  if (config.devices.simulated()) return std::make_unique<Platform>(config);
  return std::make_unique<Platform>(config, make_driver_devices(config));
}

}  // namespace mc::platform
