// `serve` on hardware drivers (docs/hardware.md): the live platform built on the
// driver set its configuration selects (platform/driver_registry.h), here the skeleton bench of
// tests/platform/skeleton_drivers.h, operated from the console in wall-clock time.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <thread>

#include "microcobot/live/live_platform.h"
#include "microcobot/platform/driver_registry.h"
#include "platform/skeleton_drivers.h"
#include "support/test_support.h"

namespace mc::live {
namespace {

using namespace std::chrono_literals;

std::unique_ptr<test::SkeletonBench> g_bench;

const platform::DriverRegistration kSkeletonBench{"skeleton-bench",
                                                  [](const platform::PlatformConfig& config) {
                                                    g_bench = std::make_unique<test::SkeletonBench>(config);
                                                    return g_bench->devices();
                                                  }};

TEST(LiveDrivers, TheConsoleJogsTheStageThroughTheSelectedDriversAndTheDemoIsRefused) {
  LiveParams params;
  params.platform.devices.driver = "skeleton-bench";
  LivePlatform live(params);
  ASSERT_TRUE(g_bench);
  std::mutex mutex;
  double measured_x =
      std::numeric_limits<double>::quiet_NaN();  // the driver's encoder, as the telemetry carries it
  const std::size_t x_channel = 10;
  ASSERT_EQ(platform::builtin_telemetry(false)[x_channel].name, "measured_x_m");
  live.start([&](const platform::TelemetrySample& s, std::size_t) {
    std::lock_guard lock(mutex);
    measured_x = s[x_channel];
  });
  const auto x = [&] {
    std::lock_guard lock(mutex);
    return measured_x;
  };
  ASSERT_TRUE(test::eventually([&] { return live.status().t_s > 0.1 && !std::isnan(x()); }));
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(live.status().lifecycle[i], devices::Lifecycle::kActive) << i;
  EXPECT_EQ(live.channel_count(), platform::loop_channel_count()) << "no ground truth on drivers";

  // 0.5 s of +x at 100 um/s with the deadman: the skeleton axis's encoder counts it.
  const double x0 = x();
  live.set_console_in_control(true);
  ConsoleCommand jog;
  jog.deadman = true;
  jog.velocity_m_s = {100e-6, 0, 0};
  const auto end = std::chrono::steady_clock::now() + 500ms;
  while (std::chrono::steady_clock::now() < end) {
    live.push_command(jog);
    std::this_thread::sleep_for(20ms);
  }
  jog.velocity_m_s = {0, 0, 0};  // stop, and let the telemetry (behind the loop) catch up
  for (int i = 0; i < 5; ++i) {
    live.push_command(jog);
    std::this_thread::sleep_for(20ms);
  }
  const double moved = x() - x0;
  EXPECT_GT(moved, 20e-6) << "the stage moved through the driver's registers";
  EXPECT_LT(moved, 60e-6) << "at the jog's speed, in wall-clock time";

  // The scripted demo needs the simulation's ground truth.
  live.request(ConsoleAction::kDemo);
  EXPECT_NE(live.status().last_error.find("simulated platform"), std::string::npos)
      << live.status().last_error;
  EXPECT_FALSE(live.status().demo);

  live.stop();  // every device in its safe state: the boards unpowered
  for (const auto& b : g_bench->buses) EXPECT_FALSE(b.powered);
}

}  // namespace
}  // namespace mc::live
