// The ANC300 console codec and twin against a fake stage: login, echo, OK/ERROR
// lines as pymeasure's adapter reads them, modes, stepping and stepw.

#include <gtest/gtest.h>

#include "fake_stage.h"
#include "microcobot/drivers/anc300_codec.h"
#include "microcobot/twins/anc300_twin.h"

namespace mc::twins {
namespace {

using testing::FakeStage;

TEST(Anc300Codec, ParsesAndFormats) {
  const auto r = drivers::anc300::parse_line("SETF 1 500.000\r\n");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->command, "setf");
  EXPECT_EQ(r->args, (std::vector<std::string>{"1", "500.000"}));
  EXPECT_FALSE(drivers::anc300::parse_line(" \r\n"));
  EXPECT_EQ(drivers::anc300::reply_ok({drivers::anc300::value_line("frequency", "500", "Hz")}),
            "frequency = 500 Hz\r\nOK\r\n");
  EXPECT_EQ(drivers::anc300::reply_error("Axis not in stepping mode"),
            "Axis not in stepping mode\r\nERROR\r\n");
  EXPECT_EQ(drivers::anc300::value_of("voltage = 60.000000 V"), "60.000000");
  EXPECT_FALSE(drivers::anc300::value_of("OK"));
  EXPECT_FALSE(drivers::anc300::parse_count("-3"));
  EXPECT_EQ(drivers::anc300::parse_mode("stp"), drivers::anc300::Mode::kStp);
}

struct Anc300Rig {
  FakeStage stage;
  Anc300Twin twin{stage, Anc300TwinParams{}};
  Anc300Session session;
  Anc300Rig() {
    twin.on_password(session, "123456", true);
    session.echo = false;
  }
  std::string ask(const std::string& line, ClientId c = 1) {
    return twin.on_line(c, session, line).value_or("<wait>");
  }
};

TEST(Anc300Twin, LoginAndEchoAsPymeasureReadsThem) {
  FakeStage stage;
  Anc300Twin twin(stage, {});
  Anc300Session s;
  EXPECT_NE(twin.greeting().find("Authorization code: "), std::string::npos);
  const std::string auth = twin.on_password(s, "123456", true);
  // pymeasure: ret.split('\r\n')[1] == 'Authorization success'
  EXPECT_EQ(auth, "\r\nAuthorization success\r\n> ");
  EXPECT_EQ(twin.on_line(1, s, "echo off").value(), "echo off\r\nOK\r\n");
  EXPECT_EQ(twin.on_line(1, s, "getm 1").value(), "mode = gnd\r\nOK\r\n");
  Anc300Session bad;
  EXPECT_EQ(twin.on_password(bad, "0000", false), "\r\nAuthorization failed\r\nAuthorization code: ");
  EXPECT_FALSE(bad.authorized);
}

TEST(Anc300Twin, SettingsReadBack) {
  Anc300Rig rig;
  EXPECT_EQ(rig.ask("setf 1 500.000"), "OK\r\n");
  EXPECT_EQ(rig.ask("getf 1"), "frequency = 500 Hz\r\nOK\r\n");
  EXPECT_EQ(rig.ask("setv 1 60.000"), "OK\r\n");
  EXPECT_EQ(rig.ask("getv 1"), "voltage = 60.000000 V\r\nOK\r\n");
  EXPECT_EQ(rig.ask("setm 1 stp"), "OK\r\n");
  EXPECT_EQ(rig.ask("getm 1"), "mode = stp\r\nOK\r\n");
  EXPECT_EQ(rig.ask("setv 1 150"), "Value out of range (voltage: 0 to 100 V, the amplifier's)\r\nERROR\r\n");
  EXPECT_EQ(rig.ask("setf 1 0"), "Value out of range (frequency: 1 to 10000 Hz)\r\nERROR\r\n");
  EXPECT_EQ(rig.ask("getf 9").substr(0, 12), "Invalid axis");
  EXPECT_EQ(rig.ask("bogus 1"), "Unknown command 'bogus'\r\nERROR\r\n");
  EXPECT_EQ(rig.ask("setm 1 inp").substr(0, 8), "Mode not");
  EXPECT_NE(rig.ask("getc 1").find("capacitance = "), std::string::npos);
}

TEST(Anc300Twin, StepsOnlyInStepModeAndStepwWaits) {
  Anc300Rig rig;
  EXPECT_EQ(rig.ask("stepu 1 100"), "Axis not in stepping mode (setm N stp)\r\nERROR\r\n");
  rig.ask("setm 1 stp");
  rig.ask("setf 1 500");
  rig.ask("setv 1 60");
  EXPECT_EQ(rig.ask("stepu 1 100"), "OK\r\n");
  EXPECT_EQ(rig.stage.log.back(), "step 0 60 500 1 100");
  EXPECT_EQ(rig.ask("stepw 1"), "<wait>");
  EXPECT_EQ(rig.twin.waiting_axis(), 0);
  EXPECT_FALSE(rig.twin.poll_wait(rig.session, 0));
  rig.stage.axes[0].stepping = false;
  EXPECT_EQ(rig.twin.poll_wait(rig.session, 0).value(), "OK\r\n");
  rig.ask("stepd 1 7");
  EXPECT_EQ(rig.stage.log.back(), "step 0 60 500 -1 7");
  EXPECT_EQ(rig.ask("stepu 1 0").substr(0, 18), "Value out of range");
  EXPECT_EQ(rig.ask("stop 1"), "OK\r\n");
  EXPECT_EQ(rig.stage.log.back(), "stop");
}

TEST(Anc300Twin, HaltedAndOutrankedStepsAnswerError) {
  Anc300Rig rig;
  rig.ask("setm 2 stp");
  rig.stage.is_halted = true;
  EXPECT_EQ(rig.ask("stepu 2 10"), "Platform halted (emergency stop latched)\r\nERROR\r\n");
  rig.stage.is_halted = false;
  rig.stage.console = true;
  EXPECT_EQ(rig.ask("stepu 2 10"), "Another operator controls the stage\r\nERROR\r\n");
}

// The rotary positioner (theta) on axis 4, stepped like the others.
TEST(Anc300Twin, TheRotaryPositionerStepsOnAxis4) {
  Anc300Rig rig;
  EXPECT_EQ(rig.ask("getm 4"), "mode = gnd\r\nOK\r\n");
  rig.ask("setm 4 stp");
  rig.ask("setf 4 800");
  rig.ask("setv 4 45");
  EXPECT_EQ(rig.ask("stepd 4 250"), "OK\r\n");
  EXPECT_EQ(rig.stage.log.back(), "step 3 45 800 -1 250");
  EXPECT_EQ(rig.ask("stepw 4"), "<wait>");
  EXPECT_EQ(rig.twin.waiting_axis(), 3);
  rig.stage.axes[3].stepping = false;
  EXPECT_EQ(rig.twin.poll_wait(rig.session, 3).value(), "OK\r\n");
  rig.stage.axes[3].position = 0.5;  // rad
  EXPECT_EQ(rig.ask("getpos 4"), "position = 2.864788976e+01 deg\r\nOK\r\n");
  EXPECT_EQ(rig.ask("getser 4"), "serial number = TWIN-AXIS-4\r\nOK\r\n");
  EXPECT_EQ(rig.ask("getf 5"), "Invalid axis '5' (axes 1 to 4)\r\nERROR\r\n");
}

TEST(Anc300Twin, WithoutTheRotaryAxisAxis4IsInvalid) {
  FakeStage stage(/*rotary=*/false);
  Anc300Twin twin(stage, {});
  Anc300Session s;
  twin.on_password(s, "123456", true);
  s.echo = false;
  EXPECT_EQ(twin.on_line(1, s, "getm 4").value(), "Invalid axis '4' (axes 1 to 3)\r\nERROR\r\n");
  EXPECT_EQ(twin.on_line(1, s, "stepw 4").value(), "Invalid axis\r\nERROR\r\n");
  EXPECT_TRUE(stage.log.empty());
}

}  // namespace
}  // namespace mc::twins
