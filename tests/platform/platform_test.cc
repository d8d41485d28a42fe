#include "microcobot/platform/platform.h"

#include <gtest/gtest.h>

#include <fstream>

#include "microcobot/cell/pick_place_operator.h"
#include "microcobot/cell/session.h"
#include "microcobot/core/error.h"
#include "microcobot/core/mcap_reader.h"
#include "support/counting_allocator.h"
#include "support/test_support.h"

namespace mc::platform {
namespace {

std::string config_error(const std::string& yaml) {
  test::TempDir dir;
  std::ofstream(dir / "platform.yaml") << yaml;
  try {
    load_platform_config(dir / "platform.yaml");
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), ExitCode::kInvalidInput);
    return e.what();
  }
  return "no error";
}

TEST(PlatformConfig, BadConfigurationIsOneLineNamingTheKey) {
  const PlatformConfig defaults;
  EXPECT_NO_THROW(defaults.validate());
  EXPECT_NE(config_error("teleop:\n  motion_scael: 0.01\n").find("platform.yaml:2"), std::string::npos);
  EXPECT_NE(config_error("teleop:\n  motion_scael: 0.01\n").find("motion_scael"), std::string::npos);
  EXPECT_NE(config_error("loop:\n  base_rate_Hz: fast\n").find("base_rate_Hz"), std::string::npos);
  EXPECT_NE(config_error("teleop: {motion_scale: -1}\n").find("teleop.motion_scale"), std::string::npos);
  EXPECT_NE(config_error("loop: {slave_divisor: 5}\n").find("stage.control.control_rate_Hz"),
            std::string::npos);
  EXPECT_NE(config_error("stickslip_params_file: missing.yaml\n").find("missing.yaml"), std::string::npos);
  for (const auto& yaml : {"teleop:\n  motion_scael: 0.01\n", "loop: {slave_divisor: 5}\n"}) {
    EXPECT_EQ(config_error(yaml).find('\n'), std::string::npos);
  }
}

TEST(PlatformConfig, ANamedStickSlipFileIsReadRelativeToTheConfiguration) {
  test::TempDir dir;
  std::ofstream(dir / "axis.yaml") << "slider:\n  stroke_m: 0.02\n";
  std::ofstream(dir / "platform.yaml") << "stickslip_params_file: axis.yaml\n";
  const auto c = load_platform_config(dir / "platform.yaml");
  EXPECT_DOUBLE_EQ(axis_params(c).slider.stroke_m, 0.02);
}

// The platform with the scripted operator attached, as `microcobot run` builds it.
struct Rig {
  PlatformConfig config;
  Platform platform{config};
  cell::PickPlaceOperator op{platform, cell::PickPlaceOperatorParams{}};
  Rig() {
    platform.set_operator([this](const runtime::TickInfo& t) { op.act(t); });
  }
};

TEST(Platform, TheLoopPathNeitherAllocatesNorLocks) {
  Rig rig;
  rig.platform.loop().run_for(1000);  // warm-up: first touches
  std::size_t allocations = 0;
  {
    test::AllocationGuard guard;
    rig.platform.loop().run_for(20000);  // 2 s: approach and clutch-free steering, all devices
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_GT(rig.platform.teleop().slave_target_m.x(), 100e-6);  // the operator did drive the slave
  // The telemetry left through the ring (the drain is off the loop).
  Platform& p = rig.platform;
  EXPECT_EQ(p.telemetry_dropped(), 0u);
}

TEST(Platform, AFaultingDevicePutsEveryDeviceInItsSafeState) {
  Rig rig;
  Platform& p = rig.platform;
  p.loop().run_for(5000);
  ASSERT_FALSE(p.faulted());
  p.tweezers().fault();  // e.g. the TéléTweez driver lost its encoder
  p.loop().run_for(1);
  EXPECT_TRUE(p.faulted());
  for (int i = 0; i < 3; ++i) EXPECT_EQ(p.axis(i).state(), devices::Lifecycle::kFault);
  EXPECT_EQ(p.haptic().state(), devices::Lifecycle::kFault);
  EXPECT_EQ(p.gripper().state(), devices::Lifecycle::kFault);
  const double x = p.simulation().axes[0]->true_position_m();
  p.loop().run_for(1000);
  for (int i = 0; i < 3; ++i)
    EXPECT_DOUBLE_EQ(p.simulation().axes[static_cast<std::size_t>(i)]->voltage_V(), 0.0);  // axes at 0 V
  EXPECT_DOUBLE_EQ(p.simulation().haptic->channels().f_m_N, 0.0);                          // no force
  EXPECT_DOUBLE_EQ(p.simulation().haptic->channels().u_V, 0.0);
  EXPECT_NEAR(p.simulation().axes[0]->true_position_m(), x, 2e-6);  // at most the PE's retraction
}

TEST(Platform, StaleHapticReadingsHoldTheSlaveAndZeroTheForceWithinTheWatchdogTimeout) {
  Rig rig;
  Platform& p = rig.platform;
  p.loop().run_for(10000);
  ASSERT_TRUE(p.teleop().engaged);
  p.simulation().haptic->freeze_readings(true);
  const int timeout = p.config().loop.watchdog_ticks;
  p.loop().run_for(static_cast<std::uint64_t>(timeout));
  EXPECT_TRUE(p.teleop().engaged);  // a few missed readings are tolerated
  p.loop().run_for(2);
  EXPECT_TRUE(p.teleop().stale);
  EXPECT_FALSE(p.teleop().engaged);
  const double held = p.teleop().slave_target_m.x();
  p.loop().run_for(5000);
  EXPECT_DOUBLE_EQ(p.teleop().slave_target_m.x(), held);
  EXPECT_DOUBLE_EQ(p.teleop().haptic_force_N.norm(), 0.0);
  p.simulation().haptic->freeze_readings(false);
  p.loop().run_for(2);
  EXPECT_TRUE(p.teleop().engaged);
}

TEST(Session, AShortPickAndPlaceSucceedsAndWritesItsReport) {
  PlatformConfig c;
  c.world.target_m.x() = 0.3e-3;  // a 300 um transport keeps the test short
  cell::Session s(c, cell::SessionParams{});
  const auto r = s.run();
  EXPECT_TRUE(r.success) << r.verdict;
  EXPECT_LT(r.placement_error_m, 5e-6);
  EXPECT_FALSE(r.crashed);
  EXPECT_EQ(r.telemetry_dropped, 0u);
  EXPECT_EQ(s.op().phase(), cell::PickPlaceOperator::Phase::kDone);
  test::TempDir dir;
  s.write(dir.path(), r);
  EXPECT_TRUE(std::filesystem::exists(dir / "index.html"));
  EXPECT_TRUE(std::filesystem::exists(dir / "recording.csv"));
  const auto mcap = read_mcap(dir / "recording.mcap");  // the same samples, checked strictly
  EXPECT_EQ(mcap.messages.size(), s.platform().recording().size());
  EXPECT_EQ(mcap.statistics.message_count, s.platform().recording().size());
  const auto j = r.to_json();
  for (const char* k : {"success", "placement_error_m", "ticks", "overruns", "tick_p99_us"})
    EXPECT_TRUE(j.contains(k));
}

TEST(Session, UnknownScenarioIsAUsageError) {
  cell::SessionParams sp;
  sp.scenario = "juggle";
  EXPECT_THROW(sp.validate(), UsageError);
}

}  // namespace
}  // namespace mc::platform
