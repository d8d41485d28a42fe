// The PiezoGripper's tips levelled by touch on the platform (Platform::start_tip_levelling): the
// Z axis brings the misaligned tips down onto the substrate, the higher tip's align drive lowers it,
// and the sequence obeys the automatic sequences' rules: the console's deadman, holding at its end,
// a fault, the contact limits.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "microcobot/platform/platform.h"

namespace mc::platform {
namespace {

using State = TipLevellingStatus::State;

struct LevellingRig {
  PlatformConfig config;
  std::unique_ptr<Platform> platform;
  teleop::ConsoleInput in;
  double peak_tip_N = 0.0;  ///< the highest tip contact seen at any operator tick
  /// Beside the part, the tips' reference `height_m` above the substrate.
  explicit LevellingRig(double misalignment_m = 20e-6, double height_m = 60e-6,
                        const microworld::TipAlignmentParams& alignment = {}) {
    config.world.gripper.tip_misalignment_m = misalignment_m;
    config.stage.home_x_m = -1e-3;
    config.stage.home_z_m = height_m;
    config.alignment = alignment;
    platform = std::make_unique<Platform>(config);
    in.active = in.fresh = in.deadman = true;
    platform->set_operator([this](const runtime::TickInfo&) {
      platform->set_console_input(in);
      const auto tips = platform->gripper().tip_contact_N();
      peak_tip_N = std::max({peak_tip_N, tips[0], tips[1]});
    });
    platform->set_console_input(in);
    platform->run(0.05);  // settled in hold
  }
  const TipLevellingStatus& status() const { return platform->tip_levelling(); }
  double tip_z() const { return platform->simulation().gripper->tip_position_m().z(); }
  double misalignment() const { return platform->simulation().gripper->tip_misalignment_m(); }
  // Runs until the levelling is no longer running, at most `max_s` of loop time.
  void run_while_levelling(double max_s) {
    for (double t = 0.0; t < max_s && platform->tip_levelling_running(); t += 0.1) platform->run(0.1);
  }
};

TEST(TipLevelling, LevelsTwentyMicrometresOfMisalignmentToWithinOneAndEndsHoldingAboveTheSubstrate) {
  LevellingRig rig;
  ASSERT_NEAR(rig.misalignment(), 20e-6, 1e-12);
  ASSERT_TRUE(rig.platform->start_tip_levelling());
  rig.run_while_levelling(120.0);
  const TipLevellingStatus& s = rig.status();
  std::printf("levelling: %s in %d passes, misalignment %.3f -> %.3f um, peak tip contact %.1f uN\n",
              to_string(s.state), s.passes, 1e6 * s.misalignment_before_m, 1e6 * s.misalignment_m,
              1e6 * s.peak_contact_N);
  ASSERT_EQ(s.state, State::kDone) << s.failure;
  EXPECT_GE(s.passes, 2);  // the check pass found the creep of the first correction
  EXPECT_LT(std::abs(s.misalignment_m), 1e-6);
  EXPECT_LT(std::abs(rig.misalignment()), 1e-6);
  EXPECT_NEAR(s.misalignment_before_m, 20e-6, 1e-12);
  EXPECT_LT(rig.peak_tip_N, rig.config.alignment.max_contact_N);
  EXPECT_GE(rig.peak_tip_N, rig.config.alignment.contact_threshold_N);  // both touched
  // Finger 1's drive took the correction; the tips left lifted off the substrate, holding there.
  EXPECT_LT(rig.platform->gripper().align_V()[1], -10.0);
  EXPECT_DOUBLE_EQ(rig.platform->gripper().align_V()[0], 0.0);
  const double z = rig.tip_z();
  EXPECT_GT(z, 10e-6);  // the low tip (half the misalignment below) off the substrate
  rig.platform->run(1.0);
  EXPECT_NEAR(rig.tip_z(), z, 0.5e-6);
  const auto tips = rig.platform->gripper().tip_contact_N();
  EXPECT_DOUBLE_EQ(tips[0] + tips[1], 0.0);
}

TEST(TipLevelling, ReleasingTheDeadmanMidSequenceHoldsEveryAxisAndTheDrives) {
  LevellingRig rig;
  ASSERT_TRUE(rig.platform->start_tip_levelling());
  // Until the higher tip's drive is lowering it (the low tip on the substrate).
  for (int i = 0; i < 1000 && rig.status().phase != microworld::AlignmentPhase::kLevel; ++i)
    rig.platform->run(0.01);
  ASSERT_EQ(rig.status().phase, microworld::AlignmentPhase::kLevel);
  rig.platform->run(0.2);
  rig.in.deadman = false;
  rig.platform->run(0.01);
  const TipLevellingStatus& s = rig.status();
  EXPECT_EQ(s.state, State::kFailed);
  EXPECT_NE(std::string(s.failure).find("deadman"), std::string::npos) << s.failure;
  const auto drives = rig.platform->gripper().align_V();
  EXPECT_LT(drives[1], 0.0);
  std::array<double, 3> at{};
  for (int i = 0; i < 3; ++i) at[i] = rig.platform->simulation().axes[i]->true_position_m();
  const auto pressed = rig.platform->gripper().tip_contact_N();
  rig.platform->run(1.0);
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(rig.platform->simulation().axes[i]->true_position_m(), at[i], 0.2e-6) << "axis " << i;
  EXPECT_EQ(rig.platform->gripper().align_V(), drives);
  const auto now = rig.platform->gripper().tip_contact_N();
  EXPECT_NEAR(now[0], pressed[0], 10e-6);  // the press stays what it was (the stage holds)
  EXPECT_LT(rig.peak_tip_N, rig.config.alignment.max_contact_N);
  // Without the deadman it is refused, and says why.
  EXPECT_FALSE(rig.platform->start_tip_levelling());
  EXPECT_NE(std::string(rig.status().failure).find("deadman"), std::string::npos);
}

TEST(TipLevelling, AFaultStopsItAndAnAlignDriveAtItsLimitFailsItUnderTheForceLimit) {
  LevellingRig rig;
  ASSERT_TRUE(rig.platform->start_tip_levelling());
  rig.platform->run(1.0);
  rig.platform->fault_all();
  EXPECT_EQ(rig.status().state, State::kFailed);
  EXPECT_FALSE(rig.platform->tip_levelling_running());
  EXPECT_FALSE(rig.platform->start_tip_levelling());

  // 200 um of misalignment: more than a drive's 150 V lowers its tip. The sequence presses the low
  // tip, ramps the other drive to its limit, and stops there, every axis holding.
  LevellingRig far(200e-6, 110e-6);  // the low tip 10 um above the substrate
  ASSERT_TRUE(far.platform->start_tip_levelling());
  far.run_while_levelling(60.0);
  EXPECT_EQ(far.status().state, State::kFailed);
  EXPECT_NE(std::string(far.status().failure).find("limit"), std::string::npos) << far.status().failure;
  EXPECT_DOUBLE_EQ(far.platform->gripper().align_V()[1], -150.0);
  const double z = far.tip_z();
  far.platform->run(1.0);
  EXPECT_NEAR(far.tip_z(), z, 0.2e-6);
  EXPECT_LT(far.peak_tip_N, far.config.alignment.max_contact_N);
}

TEST(TipLevelling, TheTipsNeverPressBeyondTheProceduresLimitWhateverItsThreshold) {
  // A touch threshold 5 uN under the limit, approached ten times faster than by default: the stage,
  // which does not stop within a tick, would carry the press past the limit after the procedure
  // saw it; the platform stops the sequence ahead of it, every axis holding.
  microworld::TipAlignmentParams close;
  close.contact_threshold_N = 95e-6;
  close.max_contact_N = 100e-6;
  close.approach_m_s = 200e-6;
  LevellingRig rig(20e-6, 60e-6, close);
  ASSERT_TRUE(rig.platform->start_tip_levelling());
  rig.run_while_levelling(60.0);
  std::printf("threshold 95 uN, limit 100 uN: %s (%s), peak tip contact %.1f uN\n",
              to_string(rig.status().state), rig.status().failure, 1e6 * rig.peak_tip_N);
  EXPECT_FALSE(rig.platform->tip_levelling_running());
  EXPECT_EQ(rig.status().state, State::kFailed);
  EXPECT_LT(rig.peak_tip_N, rig.config.alignment.max_contact_N);
  const double z = rig.tip_z();
  rig.platform->run(0.5);
  EXPECT_NEAR(rig.tip_z(), z, 0.2e-6);
}

}  // namespace
}  // namespace mc::platform
