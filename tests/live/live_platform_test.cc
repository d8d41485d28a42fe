#include "microcobot/live/live_platform.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <mutex>
#include <thread>

#include "support/counting_allocator.h"
#include "support/sanitizers.h"
#include "support/test_support.h"

namespace mc::live {
namespace {

using namespace std::chrono_literals;
using devices::Lifecycle;

std::size_t channel(const char* name) { return platform::telemetry_channel_index(name); }

// The platform live, with the latest telemetry sample kept for the test to read.
struct Live {
  LiveParams params;  // named: GCC 12 warns (falsely) on a temporary's vectors here
  LivePlatform live{params};
  std::mutex mutex;
  platform::TelemetrySample last{};
  std::size_t samples = 0;
  Live() {
    live.start([this](const platform::TelemetrySample& s, std::size_t) {
      std::lock_guard lock(mutex);
      last = s;
      ++samples;
    });
  }
  double get(const char* name) {
    std::lock_guard lock(mutex);
    return last[channel(name)];
  }
  std::size_t sample_count() {
    std::lock_guard lock(mutex);
    return samples;
  }
  // Waits until the telemetry (which reaches the sink through the drain thread, behind the
  // loop) shows the loop's state of now: a sample 20 ms of live time newer than the status.
  bool catch_up() {
    const double t = live.status().t_s;
    return test::eventually([&] { return get("t_s") > t + 0.02; });
  }
  // Sends `c` at 50 Hz for `duration` (the console's heartbeat).
  void drive(const ConsoleCommand& c, std::chrono::milliseconds duration) {
    const auto end = std::chrono::steady_clock::now() + duration;
    while (std::chrono::steady_clock::now() < end) {
      live.push_command(c);
      std::this_thread::sleep_for(20ms);
    }
  }
};

ConsoleCommand jog(double vx, bool deadman = true) {
  ConsoleCommand c;
  c.deadman = deadman;
  c.velocity_m_s = {vx, 0, 0};
  return c;
}

TEST(LivePlatform, TheConsoleJogsTheStageInWallClockTimeOnlyWithTheDeadmanAndFreshCommands) {
  Live rig;
  ASSERT_TRUE(test::eventually([&] { return rig.sample_count() > 50; }))
      << "the loop runs paced and streams telemetry";
  const double x0 = rig.get("target_x_m");
  rig.live.set_console_in_control(true);
  rig.drive(jog(100e-6, /*deadman=*/false), 300ms);
  EXPECT_DOUBLE_EQ(rig.get("target_x_m"), x0) << "no deadman, no motion";

  // The sample the start is read from is the loop's present, not one the drain thread still
  // holds back (a stale start would count time the stage did not jog).
  ASSERT_TRUE(rig.catch_up());
  const double t0 = rig.get("t_s");
  const auto wall0 = std::chrono::steady_clock::now();
  rig.drive(jog(100e-6), 1000ms);
  const double moved = rig.get("target_x_m") - x0, elapsed = rig.get("t_s") - t0;
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  // Paced to the wall clock: never ahead of it (the drive's own wall time: its 20 ms sleeps
  // overshoot on a loaded machine, 1.175 s in a cold CI run); behind it only when the machine
  // cannot keep up (sanitizer builds, loaded CI machines), when the loop skips rather than bursts.
  EXPECT_LT(elapsed, wall + 0.05) << "the loop ran ahead of the wall clock (" << wall << " s)";
  // Under ASan beside another paced test a loop tick can take most of its period (CI-like run:
  // 0.36 s of loop time in 1 s).
  EXPECT_GT(elapsed, MC_UNDER_SANITIZER ? 0.2 : 0.4) << "the loop hardly ran";
#if MC_UNDER_SANITIZER
  // Under ASan on a loaded machine this thread's 50 Hz heartbeat can starve past the 0.2 s
  // timeout: the stage then holds, as it must (an ASan run: 43 um in 0.67 s of loop
  // time). Never faster than asked, and jogging for most of the run.
  EXPECT_LE(moved, 100e-6 * elapsed + 1e-6);
  EXPECT_GT(moved, 0.3 * 100e-6 * elapsed);
#else
  EXPECT_NEAR(moved, 100e-6 * elapsed, 15e-6);
  EXPECT_TRUE(rig.live.status().console_fresh);  // (under ASan the heartbeat may have starved)
#endif

  // The client goes silent: after the command timeout the stage holds.
  std::this_thread::sleep_for(300ms);
  EXPECT_TRUE(test::eventually([&] { return !rig.live.status().console_fresh; }));
  ASSERT_TRUE(rig.catch_up());
  const double held = rig.get("target_x_m");
  std::this_thread::sleep_for(200ms);
  EXPECT_DOUBLE_EQ(rig.get("target_x_m"), held);
  EXPECT_NEAR(rig.get("measured_x_m"), held, 3e-6) << "the slave reached the held target";
}

TEST(LivePlatform, TheEstopLatchesEveryDeviceInItsSafeStateUntilAnExplicitReset) {
  Live rig;
  rig.live.set_console_in_control(true);
  rig.drive(jog(200e-6), 300ms);
  rig.live.estop();
  ASSERT_TRUE(test::eventually([&] { return rig.live.status().estopped; }));
  auto s = rig.live.status();
  for (Lifecycle l : s.lifecycle) EXPECT_EQ(l, Lifecycle::kFault);
  ASSERT_TRUE(rig.catch_up());
  const double held = rig.get("target_x_m");
  rig.drive(jog(200e-6), 300ms);  // commands with the deadman: nothing moves
  EXPECT_DOUBLE_EQ(rig.get("target_x_m"), held);
  EXPECT_EQ(rig.get("u_x_V"), 0.0);
  EXPECT_TRUE(rig.live.status().estopped) << "latched";
  // A new scene is no way out of it: the demo and a restart are refused while it holds.
  for (ConsoleAction a : {ConsoleAction::kDemo, ConsoleAction::kRestart}) {
    rig.live.request(a);
    EXPECT_NE(rig.live.status().last_error.find("reset first"), std::string::npos)
        << rig.live.status().last_error;
  }
  std::this_thread::sleep_for(200ms);
  s = rig.live.status();
  EXPECT_TRUE(s.estopped) << "still latched";
  EXPECT_FALSE(s.demo);
  for (Lifecycle l : s.lifecycle) EXPECT_EQ(l, Lifecycle::kFault);

  rig.live.request(ConsoleAction::kReset);
  EXPECT_TRUE(test::eventually([&] { return !rig.live.status().estopped; }));
  s = rig.live.status();
  EXPECT_FALSE(s.estopped) << s.last_error;
  for (Lifecycle l : s.lifecycle) EXPECT_EQ(l, Lifecycle::kActive);
  // The reset re-takes the target where the stage stands, which lags the held target by the
  // jog's tracking error (20 um in a CI run): the jog is measured from there.
  ASSERT_TRUE(rig.catch_up());
  const double restart = rig.get("target_x_m");
  rig.drive(jog(200e-6), 600ms);
  ASSERT_TRUE(rig.catch_up());
  // 120 um asked; under ASan on a loaded machine the loop runs a third of the wall time and the
  // heartbeat may starve (see the jog test above).
  EXPECT_GT(rig.get("target_x_m"), restart + (MC_UNDER_SANITIZER ? 10e-6 : 60e-6))
      << "driven again after the reset";
}

TEST(LivePlatform, TheLoopThreadNeverAllocatesWhileCommandsAndTelemetryFlow) {
  Live rig;
  rig.live.set_console_in_control(true);
  rig.drive(jog(100e-6), 200ms);  // warm-up: every path touched once
  std::size_t allocations = 0;
  ASSERT_NE(rig.live.loop_thread_id(), std::thread::id{});
  ASSERT_NE(rig.live.loop_thread_id(), std::this_thread::get_id());
  {
    test::AllocationGuard guard(rig.live.loop_thread_id());
    ConsoleCommand c = jog(-100e-6);
    c.has_gripper = true;
    c.gripper_opening_m = 300e-6;
    rig.drive(c, 500ms);
    c.has_goal = true;
    c.goal_m = {0, 0, 1e-3};
    rig.drive(c, 300ms);
    rig.live.estop();
    EXPECT_TRUE(test::eventually([&] { return rig.live.status().estopped; }));
    std::this_thread::sleep_for(20ms);  // the faulted loop ticks on
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_GT(rig.sample_count(), 500u) << "telemetry kept flowing";
}

TEST(LivePlatform, TheDemoRestartsTheSceneWithTheScriptedOperatorAndTimeGoesOn) {
  Live rig;
  std::this_thread::sleep_for(200ms);
  const double t = rig.get("t_s");
  rig.live.request(ConsoleAction::kDemo);
  // The rebuild takes about a second (longer in a sanitized build on a loaded machine).
  EXPECT_TRUE(test::eventually([&] { return rig.live.status().restarts == 1; }));
  std::this_thread::sleep_for(200ms);
  const auto s = rig.live.status();
  EXPECT_TRUE(s.demo);
  EXPECT_EQ(s.restarts, 1u);
  EXPECT_EQ(s.demo_phase, "approach");
  EXPECT_GT(rig.get("t_s"), t) << "live time continues across the restart";
  EXPECT_TRUE(std::isfinite(rig.get("part_x_m")));
}

// A finished demo hands control back with every axis holding, and says how it ended.
TEST(LivePlatform, AFinishedDemoHandsBackWithEveryAxisHoldingAndReportsItsOutcome) {
  LiveParams params;
  params.paced = false;  // as fast as the machine goes: the whole insertion in seconds
  params.platform.world = microworld::pin_in_hole_scene();
  params.platform.world.target_m.x() = 0.3e-3;
  LivePlatform live(params);
  std::mutex mutex;
  platform::TelemetrySample last{};
  live.start([&](const platform::TelemetrySample& s, std::size_t) {
    std::lock_guard lock(mutex);
    last = s;
  });
  auto get = [&](const char* name) {
    std::lock_guard lock(mutex);
    return last[channel(name)];
  };
  live.request(ConsoleAction::kDemo);
  ASSERT_TRUE(test::eventually(
      [&] {
        const auto o = live.status().demo_result.outcome;
        return o != DemoResult::Outcome::kNone && o != DemoResult::Outcome::kRunning;
      },
      std::chrono::seconds(120)));
  const LiveStatus s = live.status();
  EXPECT_EQ(s.demo_result.outcome, DemoResult::Outcome::kInserted)
      << s.demo_result.phase << ": " << s.demo_result.reason;
  EXPECT_FALSE(s.demo);
  EXPECT_FALSE(s.demo_result.reason.empty());
  EXPECT_LT(s.demo_result.placement_error_m, 10e-6);
  EXPECT_GT(s.demo_result.duration_s, 1.0);
  // Once the last motion has settled (half a second), nothing moves for three seconds: no axis
  // drifts (a held stick-slip axis stays within nanometres), the coupling is off.
  const double t_end = get("t_s");
  ASSERT_TRUE(test::eventually([&] { return get("t_s") > t_end + 0.5; }, std::chrono::seconds(60)));
  const double t0 = get("t_s");
  const std::array<double, 3> p0 = {get("slave_x_m"), get("slave_y_m"), get("slave_z_m")};
  ASSERT_TRUE(test::eventually([&] { return get("t_s") > t0 + 3.0; }, std::chrono::seconds(60)));
  EXPECT_NEAR(get("slave_x_m"), p0[0], 50e-9);
  EXPECT_NEAR(get("slave_y_m"), p0[1], 50e-9);
  EXPECT_NEAR(get("slave_z_m"), p0[2], 50e-9);
  EXPECT_EQ(get("engaged"), 0.0);
  live.stop();
}

TEST(LivePlatform, ADemoThatCannotWorkInTheSceneIsRefusedWithItsReason) {
  LiveParams params;
  params.paced = false;
  platform::use_optical_trap_scene(params.platform);
  LivePlatform live(params);
  EXPECT_NE(live.demo_unavailable_reason().find("optical-trap"), std::string::npos);
  live.request(ConsoleAction::kDemo);
  EXPECT_EQ(live.status().last_error, live.demo_unavailable_reason());
  EXPECT_EQ(live.status().demo_result.outcome, DemoResult::Outcome::kNone);
}

}  // namespace
}  // namespace mc::live
