// The MCS2 codec and twin against a fake stage: the protocol's contract (commands split at ';',
// set commands unanswered, one line per query, the error queue's codes and texts, positions as
// 64-bit integers in pm and ndeg), the channel state bits through a reference, an unreferenced
// channel, a channel without sensor stepping open loop, STOP, and refusals.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <regex>
#include <thread>

#include "fake_stage.h"
#include "microcobot/drivers/mcs2_codec.h"
#include "microcobot/twins/mcs2_twin.h"

namespace mc::twins {
namespace {

namespace mcs2 = drivers::mcs2;
namespace bit = drivers::mcs2::channel_state;
using testing::FakeStage;

TEST(Mcs2Codec, SplitsLinesAndParsesHeadersSuffixesAndParameters) {
  EXPECT_EQ(mcs2::split_commands(":DEV:NOCH?; :CHAN0:VEL 5 ;;\r\n").size(), 2u);
  mcs2::Command c;
  ASSERT_EQ(mcs2::parse_command(":CHAN0:POS:CURR?", c), mcs2::kNoError);
  EXPECT_EQ(c.header, "CHAN:POS:CURR");
  EXPECT_EQ(c.index, 0);
  EXPECT_TRUE(c.query);
  ASSERT_EQ(mcs2::parse_command("channel12:Position:TARGET?", c), mcs2::kNoError);  // long forms, any case
  EXPECT_EQ(c.header, "CHAN:POS:TARG");
  EXPECT_EQ(c.index, 12);
  ASSERT_EQ(mcs2::parse_command(":MOVE2 1000000.000000", c), mcs2::kNoError);
  EXPECT_EQ(c.header, "MOVE");
  EXPECT_FALSE(c.query);
  EXPECT_EQ(c.args, (std::vector<std::string>{"1000000.000000"}));
  EXPECT_EQ(mcs2::parse_command(":CHAN0:\x01STAT?", c), mcs2::kInvalidCharacter);
  EXPECT_EQ(mcs2::parse_command(":CHAN0:", c), mcs2::kUndefinedHeader);
  EXPECT_EQ(mcs2::parse_command(":CHAN1:MOD2:STAT?", c), mcs2::kUndefinedHeader);
  EXPECT_EQ(mcs2::parse_command(":CHAN1234:STAT?", c), mcs2::kHeaderSuffixOutOfRange);
  EXPECT_EQ(mcs2::parse_command(":MOVE0 1,,2", c), mcs2::kInvalidSeparator);
}

TEST(Mcs2Codec, NumbersAndErrorReplies) {
  EXPECT_EQ(mcs2::parse_integer("9223372036854775807"), INT64_MAX);  // exact beyond 2^53
  EXPECT_FALSE(mcs2::parse_integer("1.0"));
  EXPECT_FALSE(mcs2::parse_integer("9223372036854775808"));
  EXPECT_EQ(mcs2::parse_rounded("1000000.000000"), 1000000);
  EXPECT_EQ(mcs2::parse_rounded("-2.5e3"), -2500);
  EXPECT_FALSE(mcs2::parse_rounded("1e19"));
  EXPECT_FALSE(mcs2::parse_rounded("nan"));
  EXPECT_EQ(mcs2::format_error(-113), "-113,\"Undefined header\"");
  const auto e = mcs2::parse_error_reply("274,\"Not referenced\"\r\n");
  ASSERT_TRUE(e);
  EXPECT_EQ(e->first, 274);
  EXPECT_EQ(e->second, "Not referenced");
  EXPECT_FALSE(mcs2::parse_error_reply("274,Not referenced"));
  EXPECT_EQ(mcs2::reply_end("12\r\n3"), 4u);
  EXPECT_EQ(mcs2::reply_end("12"), 0u);
  // Every text as kamzik3 reads it: ([-0-9]+),"([\w ]+)".
  const std::regex kamzik3("([-0-9]+),\"([\\w ]+)\"");
  for (int code : {0,    -101, -103, -104, -108,  -109,  -113,  -114,  -222,  -350,  -363,  0x19,
                   0x21, 0x22, 0x23, 0x25, 0x103, 0x104, 0x106, 0x112, 0x152, 0x202, 0x7ffe})
    EXPECT_TRUE(std::regex_match(mcs2::format_error(code), kamzik3)) << code;
}

struct Mcs2Rig {
  FakeStage stage;
  Mcs2Twin twin;
  explicit Mcs2Rig(Mcs2TwinParams p = {}) : twin(stage, p) {}
  std::string ask(const std::string& line, ClientId c = 1) { return twin.on_line(c, line); }
  std::string error() { return ask(":SYST:ERR:NEXT?"); }
  std::uint32_t stat(int n) {
    return static_cast<std::uint32_t>(std::stoul(ask(fmt::format(":CHAN{}:STAT?", n))));
  }
  void referenced(int n = 0) {
    ask(fmt::format(":CHAN{}:HOLD -1;:REF{}", n, n));
    stage.axes[static_cast<std::size_t>(n)].position = 0.0;
    stage.axes[static_cast<std::size_t>(n)].on_target = true;
  }
};

TEST(Mcs2Twin, SetCommandsAreUnansweredAndEachQueryGetsOneLine) {
  Mcs2Rig rig;
  EXPECT_EQ(rig.ask(":DEV:NOCH?;:DEV:NOBM?;:DEV:SNUM?"), "4\r\n2\r\n\"MCS2-00000001\"\r\n");
  EXPECT_EQ(rig.ask(":CHAN0:VEL 5000"), "");
  EXPECT_EQ(rig.ask(":CHAN0:VEL 2500.4;:CHAN0:VEL?;:CHAN0:HOLD -1;:CHAN0:HOLD?"), "2500\r\n-1\r\n");
  EXPECT_EQ(rig.ask(":SYST:ERR:COUN?"), "0\r\n");
  EXPECT_EQ(rig.ask(":DEV:STAT?"), "0\r\n");
  FakeStage three(/*rotary=*/false);
  Mcs2Twin twin(three, {});
  EXPECT_EQ(twin.on_line(1, ":DEV:NOCH?;:DEV:NOBM?"), "3\r\n1\r\n");
}

TEST(Mcs2Twin, TheErrorQueueKeepsCodesInOrderWithTheirTextsAndOverflows) {
  Mcs2Rig rig;
  EXPECT_EQ(rig.ask(":CHAN0:FOO?"), "");  // a failed query is not answered
  EXPECT_EQ(rig.ask(":CHAN7:STAT?"), "");
  EXPECT_EQ(rig.ask(":CHAN0:VEL"), "");
  EXPECT_EQ(rig.ask(":CHAN0:MMOD 9"), "");
  EXPECT_EQ(rig.ask(":SYST:ERR:COUN?"), "4\r\n");
  EXPECT_EQ(rig.ask(":SYST:ERR?;:SYST:ERR:NEXT?"),
            "-113,\"Undefined header\"\r\n34,\"Invalid channel index\"\r\n");
  EXPECT_EQ(rig.error(), "-109,\"Missing parameter\"\r\n");
  EXPECT_EQ(rig.error(), "-222,\"Data out of range\"\r\n");
  EXPECT_EQ(rig.error(), "0,\"No error\"\r\n");
  for (int i = 0; i < 25; ++i) rig.ask(":NOPE");
  EXPECT_EQ(rig.ask(":SYST:ERR:COUN?"), "20\r\n");
  for (int i = 0; i < 19; ++i) EXPECT_EQ(rig.error(), "-113,\"Undefined header\"\r\n");
  EXPECT_EQ(rig.error(), "-350,\"Queue overflow\"\r\n");
  rig.twin.on_overlong_line();
  rig.ask("*CLS");
  EXPECT_EQ(rig.ask(":SYST:ERR:COUN?"), "0\r\n");
}

TEST(Mcs2Twin, PositionsArePicometresAndNanodegreesAs64BitIntegers) {
  Mcs2Rig rig;
  rig.stage.axes[0].position = 1.5e-3;  // m
  rig.stage.axes[3].position = 0.5;     // rad
  EXPECT_EQ(rig.ask(":CHAN0:POS?;:CHAN3:POS:CURR?"), "1500000000\r\n28647889757\r\n");
  EXPECT_EQ(rig.ask(":CHAN0:TUN:BASE:UNIT?;:CHAN0:TUN:BASE:RES?"), "2\r\n-12\r\n");
  EXPECT_EQ(rig.ask(":CHAN3:TUN:BASE:UNIT?;:CHAN3:TUN:BASE:RES?"), "3\r\n-9\r\n");
  // Setting the position shifts the scale: values beyond a double's exact integers stay exact.
  rig.ask(":CHAN0:POS 900000000000000001");
  EXPECT_EQ(rig.ask(":CHAN0:POS?"), "900000000000000001\r\n");
  rig.stage.axes[0].position = 1.5e-3 + 1e-12;
  EXPECT_EQ(rig.ask(":CHAN0:POS?"), "900000000000000002\r\n");
  EXPECT_EQ(rig.ask(":CHAN0:RLIM:MAX?"), "900000003500000001\r\n");  // the +5 mm travel, shifted
}

TEST(Mcs2Twin, AnUnreferencedChannelRefusesAbsoluteMovesButMovesRelative) {
  Mcs2Rig rig;
  EXPECT_EQ(rig.stat(0), bit::kSensorPresent | bit::kAmplifierEnabled);
  rig.ask(":MOVE0 1000000");
  EXPECT_EQ(rig.error(), "274,\"Not referenced\"\r\n");
  EXPECT_TRUE(rig.stage.log.empty());
  rig.stage.axes[0].position = 1e-3;
  rig.ask(":CHAN0:MMOD 1;:MOVE0 2000000.0");
  ASSERT_EQ(rig.stage.log, (std::vector<std::string>{"move"}));
  EXPECT_NEAR(rig.stage.last_goal[0], 1.002e-3, 1e-15);
  EXPECT_NEAR(rig.stage.last_speed, 1e-4, 1e-12);  // VEL 0.1 mm/s at power-up
  EXPECT_EQ(rig.stat(0) & (bit::kActivelyMoving | bit::kIsReferenced), bit::kActivelyMoving);
  EXPECT_EQ(rig.error(), "0,\"No error\"\r\n");
}

TEST(Mcs2Twin, TheReferenceDrivesHomeAndSetsTheBits) {
  Mcs2Rig rig;
  rig.stage.axes[0].position = 2e-3;
  rig.ask(":CHAN0:HOLD -1;:CHAN0:REF:OPT 4;:REF0");
  ASSERT_EQ(rig.stage.log, (std::vector<std::string>{"move"}));
  EXPECT_EQ(rig.stage.last_goal[0], 0.0);
  const auto during = rig.stat(0);
  EXPECT_TRUE(during & bit::kReferencing);
  EXPECT_TRUE(during & bit::kActivelyMoving);
  EXPECT_TRUE(during & bit::kClosedLoopActive);
  EXPECT_FALSE(during & bit::kIsReferenced);
  rig.ask(":MOVE0 0");
  EXPECT_EQ(rig.error(), "274,\"Not referenced\"\r\n");  // not before the reference is done
  rig.stage.axes[0].position = 0.0;
  rig.stage.axes[0].on_target = true;
  EXPECT_EQ(rig.stat(0), bit::kClosedLoopActive | bit::kSensorPresent | bit::kIsReferenced |
                             bit::kAmplifierEnabled | bit::kInPosition);
  rig.ask(":CHAN0:HOLD 0");  // no hold time: the closed loop ends on the target
  EXPECT_FALSE(rig.stat(0) & bit::kClosedLoopActive);
  rig.ask(":MOVE0 -1500000000");
  EXPECT_NEAR(rig.stage.last_goal[0], -1.5e-3, 1e-15);
  EXPECT_EQ(rig.ask(":CHAN0:POS:TARG?"), "-1500000000\r\n");
}

TEST(Mcs2Twin, AMoveBeyondTheTravelGoesToTheLimitAndSaysSo) {
  Mcs2Rig rig;
  rig.referenced();
  rig.ask(":MOVE0 10000000000");  // 10 mm, the travel is +-5 mm
  EXPECT_NEAR(rig.stage.last_goal[0], 5e-3, 1e-15);
  EXPECT_EQ(rig.error(), "514,\"Range limit reached\"\r\n");
  EXPECT_TRUE(rig.stat(0) & bit::kRangeLimitReached);
  rig.ask(":MOVE0 0");
  EXPECT_FALSE(rig.stat(0) & bit::kRangeLimitReached);
}

TEST(Mcs2Twin, AChannelWithoutSensorStepsOpenLoopOnly) {
  Mcs2TwinParams p;
  p.no_sensor_channels = 0b10;
  Mcs2Rig rig(p);
  EXPECT_EQ(rig.stat(1), bit::kAmplifierEnabled);
  EXPECT_EQ(rig.ask(":CHAN1:POS?"), "");
  EXPECT_EQ(rig.error(), "259,\"No sensor present\"\r\n");
  rig.ask(":REF1");
  EXPECT_EQ(rig.error(), "259,\"No sensor present\"\r\n");
  rig.ask(":CHAN1:MMOD 1;:MOVE1 100");
  EXPECT_EQ(rig.error(), "259,\"No sensor present\"\r\n");
  rig.ask(":CHAN1:MMOD 4;:CHAN1:STEP:FREQ 2000;:CHAN1:STEP:AMPL 65535;:MOVE1 -300");
  EXPECT_EQ(rig.stage.log, (std::vector<std::string>{"step 1 100 2000 -1 300"}));  // 65535: 100 V
  EXPECT_EQ(rig.stat(1), bit::kActivelyMoving | bit::kAmplifierEnabled);
  rig.ask(":MOVE1 100001");
  EXPECT_EQ(rig.error(), "-222,\"Data out of range\"\r\n");
  rig.ask(":CHAN1:SENS:MODE 1");
  EXPECT_EQ(rig.error(), "259,\"No sensor present\"\r\n");
}

TEST(Mcs2Twin, SensModeZeroDisablesTheSensorAndLeavesStepping) {
  Mcs2Rig rig;
  rig.ask(":CHAN0:SENS:MODE 0;:CHAN0:SENS:MODE?");
  EXPECT_EQ(rig.ask(":CHAN0:SENS:MODE?;:CHAN0:POS?"), "0\r\n");
  EXPECT_EQ(rig.error(), "260,\"Sensor disabled\"\r\n");
  rig.ask(":CHAN0:MMOD 4;:MOVE0 50");
  EXPECT_EQ(rig.stage.log.back(), "step 0 60 1000 1 50");
  rig.ask(":CHAN0:AMPL 0;:MOVE0 50");
  EXPECT_EQ(rig.error(), "262,\"Amplifier disabled\"\r\n");
  EXPECT_FALSE(rig.stat(0) & bit::kAmplifierEnabled);
}

TEST(Mcs2Twin, StopHoldsTheChannelWhereItIs) {
  Mcs2Rig rig;
  rig.referenced();
  rig.ask(":MOVE0 3000000000");
  rig.stage.axes[0].on_target = false;
  rig.stage.axes[0].position = 1e-3;
  rig.ask(":STOP0");
  EXPECT_EQ(rig.stage.log.back(), "stop");
  EXPECT_EQ(rig.ask(":CHAN0:POS:TARG?"), "1000000000\r\n");
}

TEST(Mcs2Twin, AStopFromAClientNotInControlStopsNothingAndLosingControlEndsTheMove) {
  Mcs2Rig rig;
  rig.referenced();
  rig.ask(":MOVE0 3000000000");
  rig.stage.axes[0].on_target = false;
  EXPECT_EQ(rig.ask(":STOP0", /*client=*/2), "");
  EXPECT_EQ(rig.stage.log.back(), "move");
  EXPECT_EQ(rig.ask(":CHAN0:POS:TARG?", 2), "3000000000\r\n");
  rig.stage.console = true;  // a console user takes control: the platform holds
  rig.stage.axes[0].position = 1e-3;
  EXPECT_EQ(rig.stat(0) & (bit::kActivelyMoving | bit::kMovementFailed), bit::kMovementFailed);
  EXPECT_EQ(rig.ask(":CHAN0:POS:TARG?"), "1000000000\r\n");
}

TEST(Mcs2Twin, AnotherOperatorOrTheEstopRefuseMovesAndFlagThem) {
  Mcs2Rig rig;
  rig.stage.console = true;
  rig.ask(":CHAN0:MMOD 1;:MOVE0 100");
  EXPECT_EQ(rig.error(), "35,\"Permission denied\"\r\n");
  EXPECT_TRUE(rig.stat(0) & bit::kMovementFailed);
  rig.stage.console = false;
  rig.stage.is_halted = true;
  rig.ask(":MOVE0 100");
  EXPECT_EQ(rig.error(), "37,\"Movement locked\"\r\n");
  EXPECT_EQ(rig.ask(":DEV:STAT?"), "2\r\n");
}

TEST(Mcs2Twin, AFailedCommandSkipsTheLinesLaterSetsButAnswersItsQueries) {
  Mcs2Rig rig;
  rig.stage.axes[0].position = 1e-3;
  EXPECT_EQ(rig.ask(":CHAN0:VEL abc;:CHAN0:MMOD 1;:MOVE0 5;:CHAN0:MMOD?"), "0\r\n");
  EXPECT_TRUE(rig.stage.log.empty());
  EXPECT_EQ(rig.error(), "-104,\"Data type error\"\r\n");
  EXPECT_EQ(rig.error(), "0,\"No error\"\r\n");
}

TEST(Mcs2Twin, CalibrationReportsCalibratingThenCalibrated) {
  Mcs2TwinParams p;
  p.calibration_s = 0.05;
  Mcs2Rig rig(p);
  rig.referenced();
  rig.ask(":CAL0");
  EXPECT_EQ(rig.stat(0) & (bit::kCalibrating | bit::kActivelyMoving | bit::kIsReferenced),
            bit::kCalibrating | bit::kActivelyMoving);
  std::this_thread::sleep_for(std::chrono::milliseconds(80));
  EXPECT_EQ(rig.stat(0) & (bit::kCalibrating | bit::kIsCalibrated), bit::kIsCalibrated);
}

}  // namespace
}  // namespace mc::twins
