#include "microcobot/platform/driver_registry.h"

#include <algorithm>
#include <map>
#include <mutex>
#include <utility>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"

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

PlatformDevices make_driver_devices(const PlatformConfig& config) {
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

std::unique_ptr<Platform> make_platform(const PlatformConfig& config) {
  if (config.devices.simulated()) return std::make_unique<Platform>(config);
  return std::make_unique<Platform>(config, make_driver_devices(config));
}

}  // namespace mc::platform
