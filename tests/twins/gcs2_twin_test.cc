// The GCS 2.0 codec and twin, line by line against a fake stage: the syntax of PI's
// manuals (multi-line replies, daisy-chain prefixes, single bytes) and the error register.

#include <gtest/gtest.h>

#include <numbers>

#include "fake_stage.h"
#include "microcobot/core/error.h"
#include "microcobot/drivers/gcs2_codec.h"
#include "microcobot/twins/gcs2_twin.h"

namespace mc::twins {
namespace {

using testing::FakeStage;

TEST(Gcs2Codec, ParsesAddressMnemonicAndArguments) {
  auto r = drivers::gcs2::parse_line("2 pos? 1 3\r");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->target_address, 2);
  EXPECT_EQ(r->mnemonic, "POS?");
  EXPECT_EQ(r->args, (std::vector<std::string>{"1", "3"}));
  EXPECT_TRUE(r->query());
  r = drivers::gcs2::parse_line("MOV 1 0.5");
  EXPECT_EQ(r->target_address, 0);
  EXPECT_FALSE(r->query());
  EXPECT_FALSE(drivers::gcs2::parse_line("   "));
}

TEST(Gcs2Codec, MultiLineRepliesEndEveryLineButTheLastInSpaceLf) {
  EXPECT_EQ(drivers::gcs2::format_reply({"1=1", "2=0", "3=1"}), "1=1 \n2=0 \n3=1\n");
  EXPECT_EQ(drivers::gcs2::format_reply({"1=0.500000"}, 2), "0 2 1=0.500000\n");
  EXPECT_TRUE(drivers::gcs2::reply_complete("1=1 \n2=0\n"));
  EXPECT_FALSE(drivers::gcs2::reply_complete("1=1 \n"));
  const auto v = drivers::gcs2::parse_axis_values("0 1 1=0.25 \n0 1 2=-1e-3\n");
  ASSERT_EQ(v.size(), 2u);
  EXPECT_EQ(v[1].first, "2");
  EXPECT_DOUBLE_EQ(v[1].second, -1e-3);
  EXPECT_THROW(drivers::gcs2::parse_axis_values("garbage\n"), InvalidInput);
  EXPECT_FALSE(drivers::gcs2::parse_number("nan"));
  EXPECT_FALSE(drivers::gcs2::parse_number("1.5x"));
  EXPECT_EQ(drivers::gcs2::error_text(10), "Controller was stopped by command");
}

struct Gcs2Rig {
  FakeStage stage;
  Gcs2Twin twin{stage, Gcs2TwinParams{}};
  std::string ask(const std::string& line, ClientId c = 1) { return twin.on_line(c, line); }
  int error() { return std::stoi(ask("ERR?")); }
};

TEST(Gcs2Twin, IdentifiesAndListsItsAxes) {
  Gcs2Rig rig;
  EXPECT_EQ(rig.ask("*IDN?"), "microcobot, E-873 digital twin, 0, 1.0\n");
  EXPECT_EQ(rig.ask("CSV?"), "2.0\n");
  EXPECT_EQ(rig.ask("SAI? ALL"), "1 \n2 \n3 \n4\n");
  const std::string help = rig.ask("HLP?");
  EXPECT_NE(help.find("MOV {<AxisID> <Position>}"), std::string::npos);
  EXPECT_EQ(help.substr(help.size() - 12), "end of help\n");
  EXPECT_EQ(rig.ask("TMX? 1"), "1=5.000000\n");
  EXPECT_EQ(rig.ask("TMN? 3"), "3=-5.000000\n");
}

TEST(Gcs2Twin, MovesOnlyWithServoOnAndReferenced) {
  Gcs2Rig rig;
  EXPECT_EQ(rig.ask("MOV 1 0.5"), "");
  EXPECT_EQ(rig.error(), drivers::gcs2::kUnallowableMove);
  EXPECT_EQ(rig.error(), 0);  // read and cleared
  rig.ask("SVO 1 1");
  EXPECT_EQ(rig.ask("SVO? 1"), "1=1\n");
  rig.ask("MOV 1 0.5");
  EXPECT_EQ(rig.error(), drivers::gcs2::kUnallowableMove);  // not referenced
  rig.ask("FRF 1");
  EXPECT_EQ(rig.twin.on_byte(1, drivers::gcs2::kReadyStatus), "\xB0\n");  // referencing: busy
  EXPECT_EQ(rig.ask("FRF? 1"), "1=0\n");
  rig.stage.axes[0].on_target = true;
  EXPECT_EQ(rig.twin.on_byte(1, drivers::gcs2::kReadyStatus), "\xB1\n");
  EXPECT_EQ(rig.ask("FRF? 1"), "1=1\n");
  rig.ask("VEL 1 0.2");
  rig.ask("MOV 1 0.5");
  EXPECT_EQ(rig.error(), 0);
  EXPECT_DOUBLE_EQ(rig.stage.last_goal[0], 0.5e-3);
  EXPECT_DOUBLE_EQ(rig.stage.last_speed, 0.2e-3);  // the moved axis' VEL
  rig.ask("MVR 1 0.25");
  EXPECT_EQ(rig.ask("MOV? 1"), "1=0.750000\n");
  rig.stage.axes[0].on_target = false;
  EXPECT_EQ(rig.twin.on_byte(1, drivers::gcs2::kMotionStatus), "1\n");
  EXPECT_EQ(rig.ask("ONT? 1"), "1=0\n");
}

TEST(Gcs2Twin, ErrorsOfPisTable) {
  Gcs2Rig rig;
  rig.ask("XYZ 1");
  EXPECT_EQ(rig.error(), drivers::gcs2::kUnknownCommand);
  EXPECT_EQ(rig.ask("POS? 7"), "");
  EXPECT_EQ(rig.error(), drivers::gcs2::kInvalidAxis);
  rig.ask("VEL 1 50");
  EXPECT_EQ(rig.error(), drivers::gcs2::kParameterOutOfRange);
  rig.ask("SVO 1 1");
  rig.stage.axes[0].on_target = true;
  rig.ask("FRF 1");
  rig.ask("FRF? 1");
  rig.ask("MOV 1 9");
  EXPECT_EQ(rig.error(), drivers::gcs2::kPositionOutOfLimits);
  rig.ask("MOV 1 abc");
  EXPECT_EQ(rig.error(), drivers::gcs2::kParameterSyntax);
  rig.ask("HLT 1");
  EXPECT_EQ(rig.error(), drivers::gcs2::kStopped);
  rig.twin.on_byte(1, drivers::gcs2::kStopAll);
  EXPECT_EQ(rig.error(), drivers::gcs2::kStopped);
  rig.stage.is_halted = true;
  rig.ask("MOV 1 0.1");
  EXPECT_EQ(rig.error(), drivers::gcs2::kStopped);  // the e-stop: the halted controller's error
  EXPECT_TRUE(rig.stage.log.size() >= 1);
}

TEST(Gcs2Twin, AnotherOperatorInControlRefusesMoves) {
  Gcs2Rig rig;
  rig.ask("SVO 1 1");
  rig.stage.axes[0].on_target = true;
  rig.ask("FRF 1", 1);
  rig.ask("FRF? 1");
  rig.stage.console = true;  // a console user took control
  rig.ask("MOV 1 0.1", 1);
  EXPECT_EQ(rig.error(), drivers::gcs2::kStopped);
  rig.stage.console = false;
  rig.ask("MOV 1 0.1", 2);  // client 1 holds control
  EXPECT_EQ(rig.error(), drivers::gcs2::kStopped);
  rig.twin.on_disconnect(1);
  rig.ask("MOV 1 0.1", 2);
  EXPECT_EQ(rig.error(), 0);
}

TEST(Gcs2Twin, DaisyChainAddressesAreHonoured) {
  Gcs2Rig rig;
  EXPECT_EQ(rig.ask("1 SAI?"), "0 1 1 \n0 1 2 \n0 1 3 \n0 1 4\n");
  EXPECT_EQ(rig.ask("2 POS?"), "");  // another controller's line
  EXPECT_EQ(rig.ask("1 ERR?"), "0 1 0\n");
}

// The rotary axis under the gripper as the controller's fourth axis, a rotation
// stage in degrees (PUN?), its limits the platform's +-62 deg (1.08 rad) and 0.16 rad/s.
struct Gcs2ThetaRig : Gcs2Rig {
  Gcs2ThetaRig() {
    ask("SVO 4 1");
    stage.axes[3].on_target = true;
    ask("FRF 4");
    ask("FRF? 4");  // referenced once on target
    stage.log.clear();
  }
};

TEST(Gcs2Twin, TheRotaryAxisIsARotationStageInDegrees) {
  Gcs2Rig rig;
  EXPECT_EQ(rig.ask("PUN?"), "1=mm \n2=mm \n3=mm \n4=deg\n");
  EXPECT_EQ(rig.ask("PUN? 4"), "4=deg\n");
  EXPECT_EQ(rig.ask("TMN? 4"), "4=-61.879442\n");  // -1.08 rad
  EXPECT_EQ(rig.ask("TMX? 4"), "4=61.879442\n");
  rig.stage.axes[3].position = -0.5;
  EXPECT_EQ(rig.ask("POS? 4"), "4=-28.647890\n");
  EXPECT_EQ(rig.ask("VEL? 4"), "4=5.000000\n");  // the power-up VEL, deg/s
  const std::string help = rig.ask("HLP?");
  EXPECT_NE(help.find("PUN? [{<AxisID>}] Get Position Unit"), std::string::npos);
  EXPECT_EQ(rig.error(), 0);
}

TEST(Gcs2Twin, MovTurnsTheRotaryAxisInDegreesConvertedExactlyToRadians) {
  Gcs2ThetaRig rig;
  rig.stage.axes[0].position = 1e-3;  // servo off on X: it is held where it is
  rig.ask("VEL 4 9");
  rig.ask("MOV 4 30");
  EXPECT_EQ(rig.error(), 0);
  ASSERT_EQ(rig.stage.log, (std::vector<std::string>{"move"}));
  EXPECT_DOUBLE_EQ(rig.stage.last_goal[3], std::numbers::pi / 6);
  EXPECT_DOUBLE_EQ(rig.stage.last_theta_speed, 9 * std::numbers::pi / 180);
  EXPECT_DOUBLE_EQ(rig.stage.last_goal[0], 1e-3);
  EXPECT_EQ(rig.ask("MOV? 4"), "4=30.000000\n");
  rig.ask("MVR 4 -45");
  EXPECT_DOUBLE_EQ(rig.stage.last_goal[3], -std::numbers::pi / 12);
  rig.stage.axes[3].on_target = false;
  EXPECT_EQ(rig.twin.on_byte(1, drivers::gcs2::kMotionStatus), "8\n");  // bit 3: axis 4 moves
  EXPECT_EQ(rig.ask("ONT? 4"), "4=0\n");
}

TEST(Gcs2Twin, RotaryGoalsAndVelocitiesOutOfItsLimitsAreRefusedWholeLines) {
  Gcs2ThetaRig rig;
  rig.ask("SVO 1 1");
  rig.stage.axes[0].on_target = true;
  rig.ask("FRF 1");
  rig.ask("FRF? 1");
  rig.stage.log.clear();
  rig.ask("MOV 4 62");  // beyond +61.88 deg
  EXPECT_EQ(rig.error(), drivers::gcs2::kPositionOutOfLimits);
  rig.ask("MOV 1 0.5 4 -70");  // a good X with a bad theta: nothing of the line is applied
  EXPECT_EQ(rig.error(), drivers::gcs2::kPositionOutOfLimits);
  EXPECT_TRUE(rig.stage.log.empty());
  EXPECT_EQ(rig.ask("MOV? 1 4"), "1=0.000000 \n4=0.000000\n");
  rig.ask("VEL 4 9.2");  // over 0.16 rad/s = 9.167 deg/s
  EXPECT_EQ(rig.error(), drivers::gcs2::kParameterOutOfRange);
  EXPECT_EQ(rig.ask("VEL? 4"), "4=5.000000\n");
  rig.ask("MOV 4 61.8");
  EXPECT_EQ(rig.error(), 0);
  EXPECT_NEAR(rig.stage.last_goal[3], 61.8 * std::numbers::pi / 180, 1e-15);
}

TEST(Gcs2Twin, WithoutTheRotaryAxisThereAreThreeAxes) {
  FakeStage stage(/*rotary=*/false);
  Gcs2Twin twin(stage, Gcs2TwinParams{});
  EXPECT_EQ(twin.on_line(1, "SAI? ALL"), "1 \n2 \n3\n");
  EXPECT_EQ(twin.on_line(1, "POS? 4"), "");
  EXPECT_EQ(twin.on_line(1, "ERR?"), "15\n");
  EXPECT_EQ(twin.on_line(1, "PUN?"), "1=mm \n2=mm \n3=mm\n");
}

}  // namespace
}  // namespace mc::twins
