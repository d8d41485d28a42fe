// Hardware drivers chosen by name from the configuration (platform/driver_registry.h): the skeleton
// bench of skeleton_drivers.h registered as a lab registers its own, selected in a YAML file,
// and the platform running on it.

#include "microcobot/platform/driver_registry.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>

#include "microcobot/core/error.h"
#include "microcobot/platform/platform_config.h"
#include "platform/skeleton_drivers.h"
#include "support/test_support.h"

namespace mc::platform {
namespace {

// The bench behind the registered factory (a lab's factory would open its boards here).
std::unique_ptr<test::SkeletonBench> g_bench;
std::string g_connection;

const DriverRegistration kSkeletonBench{"skeleton-bench", [](const PlatformConfig& config) {
                                          g_connection = config.devices.connection;
                                          g_bench = std::make_unique<test::SkeletonBench>(config);
                                          return g_bench->devices();
                                        }};

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(DriverRegistry, TheNamesAreTheSimulationThenTheRegisteredDrivers) {
  const auto names = device_driver_names();
  ASSERT_GE(names.size(), 2u);
  EXPECT_EQ(names.front(), "simulated");
  EXPECT_NE(std::find(names.begin(), names.end(), "skeleton-bench"), names.end());
  EXPECT_TRUE(is_device_driver("simulated"));
  EXPECT_TRUE(is_device_driver("skeleton-bench"));
  EXPECT_FALSE(is_device_driver("smaract"));
}

TEST(DriverRegistry, RefusesBadTakenOrReservedNamesAndMissingFactories) {
  const DeviceFactory f = [](const PlatformConfig&) { return devices::DeviceSet{}; };
  EXPECT_THROW(register_devices("", f), InvalidParams);
  EXPECT_THROW(register_devices("lab bench", f), InvalidParams);
  EXPECT_THROW(register_devices("simulated", f), InvalidParams);
  EXPECT_THROW(register_devices("skeleton-bench", f), InvalidParams);
  EXPECT_THROW(register_devices("lab-bench", DeviceFactory{}), InvalidParams);
  EXPECT_FALSE(is_device_driver("lab-bench"));
}

TEST(DriverRegistry, AConfigurationFileSelectsTheDriversAndThePlatformRunsOnThem) {
  mc::test::TempDir dir;
  mc::test::write_text(dir / "bench.yaml", "devices: {driver: skeleton-bench, connection: \"bus:0\"}\n");
  const PlatformConfig config = load_platform_config(dir / "bench.yaml");
  std::unique_ptr<Platform> p = make_platform(config);
  EXPECT_EQ(g_connection, "bus:0");
  EXPECT_FALSE(p->simulated());
  for (const auto& b : g_bench->buses) EXPECT_TRUE(b.powered);  // configured and activated
  p->loop().run_for(1000);
  ASSERT_TRUE(p->teleop().engaged);
  // The handle moves 1 mm: the X axis moves by the motion scale through the driver's registers.
  const double x0 = p->axis(0).position_m();
  g_bench->hand->handle_m.x = 1e-3;
  p->loop().run_for(5000);
  EXPECT_NEAR(p->axis(0).position_m() - x0, config.teleop.motion_scale * 1e-3, 20e-9);
  p.reset();  // deactivated: every board unpowered
  for (const auto& b : g_bench->buses) EXPECT_FALSE(b.powered);
}

TEST(DriverRegistry, AnUnknownDriverIsOneLineNamingTheKeyAndTheKnownDrivers) {
  mc::test::TempDir dir;
  mc::test::write_text(dir / "bench.yaml", "devices: {driver: smaract}\n");
  const std::string m = message_of([&] { load_platform_config(dir / "bench.yaml"); });
  EXPECT_NE(m.find("devices.driver"), std::string::npos) << m;
  EXPECT_NE(m.find("'smaract'"), std::string::npos) << m;
  EXPECT_NE(m.find("simulated, skeleton-bench"), std::string::npos) << m;
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
}

TEST(DriverRegistry, TheSimulatedPlatformRefusesAConfigurationThatSelectsDrivers) {
  PlatformConfig config;
  config.devices.driver = "skeleton-bench";
  const std::string m = message_of([&] { Platform p(config); });
  EXPECT_NE(m.find("devices.driver"), std::string::npos) << m;
  EXPECT_NE(m.find("simulated platform only"), std::string::npos) << m;
  const PlatformConfig defaults;  // named: GCC 12 warns (falsely) on a temporary's vectors
  EXPECT_TRUE(make_platform(defaults)->simulated());
}

}  // namespace
}  // namespace mc::platform
