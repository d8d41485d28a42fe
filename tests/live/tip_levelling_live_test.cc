// The console's Level tips on the live platform: the PiezoGripper's tips levelled by touch while the
// controlling client holds the deadman (Platform::start_tip_levelling through ConsoleSource), its
// result in the status, and the deadman's release holding every axis.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <string>
#include <thread>

#include "microcobot/core/error.h"
#include "microcobot/live/console_command.h"
#include "microcobot/live/live_platform.h"
#include "support/counting_allocator.h"
#include "support/live_status_wait.h"

namespace mc::live {
namespace {

using State = platform::TipLevellingStatus::State;

LiveParams misaligned_tips() {
  LiveParams p;
  p.platform.world.gripper.tip_misalignment_m = 20e-6;
  // Beside the part, the low tip 20 um above the substrate; a shorter settle than the default
  // (the first decade of the creep shows in 2 s as well, at 0.3 s a decade's start).
  p.platform.stage.home_x_m = -1e-3;
  p.platform.stage.home_z_m = 30e-6;
  p.platform.alignment.settle_s = 2.0;
  return p;
}

// The live platform and a console client in control sending its heartbeat (deadman held or not)
// at 50 Hz on a thread of its own.
struct LevellingLive {
  LiveParams params = misaligned_tips();
  LivePlatform live{params};
  std::atomic<bool> deadman{true}, quit{false};
  std::array<std::atomic<double>, 3> tool_m{};  ///< the tool's true position (telemetry slave_*_m)
  std::thread console;
  LevellingLive() {
    live.start([this](const platform::TelemetrySample& s, std::size_t) {
      const char* names[3] = {"slave_x_m", "slave_y_m", "slave_z_m"};
      for (std::size_t i = 0; i < 3; ++i) tool_m[i].store(s[test::telemetry_channel(names[i])]);
    });
    live.set_console_in_control(true);
    console = std::thread([this] {
      while (!quit.load()) {
        ConsoleCommand c;
        c.deadman = deadman.load();
        live.push_command(c);
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    });
  }
  ~LevellingLive() {
    quit.store(true);
    console.join();
    live.stop();
  }
  std::optional<platform::TipLevellingStatus> levelling() const { return live.status().levelling; }
  /// The levelling offered (the gripper has align drives) and the console driving with fresh
  /// commands: a request before its first command arrives is refused (no deadman yet), which a
  /// loaded machine (the sanitizers) makes likely.
  bool ready() {
    return test::wait_status(
        live,
        [](const LiveStatus& s) {
          return s.levelling.has_value() && s.control == "console" && s.console_fresh;
        },
        20.0);
  }
  bool wait(State s, double timeout_s) {
    return test::wait_status(
        live, [s](const LiveStatus& st) { return st.levelling && st.levelling->state == s; }, timeout_s);
  }
};

TEST(TipLevellingLive, LevelsTwentyMicrometresToWithinOneWhileTheConsoleHoldsTheDeadman) {
  LevellingLive rig;
  ASSERT_TRUE(rig.ready()) << "the simulated gripper has align drives, the console drives";
  EXPECT_NEAR(rig.levelling()->misalignment_m, 20e-6, 1e-12);
  ASSERT_TRUE(rig.live.request_tip_levelling());
  ASSERT_TRUE(rig.wait(State::kRunning, 5.0)) << rig.levelling()->failure;
  std::size_t allocations = 0;
  {
    test::AllocationGuard guard(rig.live.loop_thread_id());
    ASSERT_TRUE(test::wait_status(
        rig.live, [](const LiveStatus& s) { return s.levelling->state != State::kRunning; }, 60.0));
    allocations = guard.allocations();
  }
  const platform::TipLevellingStatus l = *rig.levelling();
  std::printf("live levelling: %s in %d passes, %.3f -> %.3f um, peak tip contact %.1f uN\n",
              platform::to_string(l.state), l.passes, 1e6 * l.misalignment_before_m, 1e6 * l.misalignment_m,
              1e6 * l.peak_contact_N);
  ASSERT_EQ(l.state, State::kDone) << l.failure;
  EXPECT_LT(std::abs(l.misalignment_m), 1e-6);
  EXPECT_NEAR(l.misalignment_before_m, 20e-6, 1e-12);
  EXPECT_GE(l.peak_contact_N, misaligned_tips().platform.alignment.contact_threshold_N);
  EXPECT_LT(l.peak_contact_N, misaligned_tips().platform.alignment.max_contact_N);
  EXPECT_EQ(allocations, 0u) << "the levelling on the loop allocates nothing";
}

TEST(TipLevellingLive, ReleasingTheDeadmanMidSequenceStopsItHoldingAndWithoutTheDeadmanItIsRefused) {
  LevellingLive rig;
  ASSERT_TRUE(rig.ready());
  ASSERT_TRUE(rig.live.request_tip_levelling());
  // Until the low tip is down and the other's drive lowers it.
  ASSERT_TRUE(test::wait_status(
      rig.live, [](const LiveStatus& s) { return s.levelling->phase == microworld::AlignmentPhase::kLevel; },
      20.0))
      << rig.levelling()->failure;
  rig.deadman.store(false);
  ASSERT_TRUE(rig.wait(State::kFailed, 2.0));
  const platform::TipLevellingStatus stopped = *rig.levelling();
  EXPECT_NE(std::string(stopped.failure).find("deadman"), std::string::npos) << stopped.failure;
  EXPECT_LT(stopped.peak_contact_N, rig.params.platform.alignment.max_contact_N);
  // Nothing moves afterwards: every axis holds (the tool within a stick-slip axis' holding jitter)
  // and the tips' misalignment stays where it was but for the creep of the drive that was ramping.
  // The telemetry reaches the sink behind the loop: read once it is past the stop.
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  std::array<double, 3> at{};
  for (std::size_t i = 0; i < 3; ++i) at[i] = rig.tool_m[i].load();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(rig.tool_m[i].load(), at[i], 0.2e-6) << "axis " << i;
  EXPECT_NEAR(rig.levelling()->misalignment_m, stopped.misalignment_m, 0.5e-6);
  // Without the deadman it does not start again, and says why.
  ASSERT_TRUE(rig.live.request_tip_levelling());
  ASSERT_TRUE(test::wait_status(
      rig.live, [](const LiveStatus& s) { return std::string(s.levelling->failure).find("refused") == 0; },
      2.0))
      << rig.levelling()->failure;
  EXPECT_EQ(rig.levelling()->state, State::kFailed);
}

TEST(TipLevellingLive, TheConsoleActionIsParsedAndAnUnknownOneIsNamed) {
  EXPECT_EQ(parse_console_action(R"({"action": "level_tips"})"), ConsoleAction::kLevelTips);
  try {
    parse_console_action(R"({"action": "level_tip"})");
    ADD_FAILURE() << "a misspelt action was accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("level_tip must be one of"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("level_tips"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mc::live
