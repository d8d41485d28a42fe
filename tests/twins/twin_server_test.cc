// The twins served on the live platform (paced loop, loopback, port 0), through raw
// sockets: a GCS closed-loop move reaches its target and reports ONT; an ANC300 login; the safety
// rules (e-stop, a console user in control, a client that disconnects mid-move); and hostile
// clients (garbage, huge lines, slowloris, half-closed sockets, a client that never reads, too
// many clients) survived while another client is still served.

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>

#include "fake_stage.h"
#include "microcobot/core/error.h"
#include "support/counting_allocator.h"
#include "twin_rig.h"

namespace mc::twins {
namespace {

using namespace std::chrono_literals;
using testing::Client;
using testing::TwinRig;

TEST(TwinServer, AGcsMoveReachesItsTargetAndReportsOnTarget) {
  TwinRig rig;
  Client c(rig.gcs_port());
  EXPECT_EQ(c.gcs("CSV?"), "2.0\n");
  rig.reference(c);
  // 0.3 s at 1 mm/s: the query right after it finds the move applied and not over, even when a
  // loaded machine under the sanitizers answers it late (50 um, 70 ms with the settle window, was
  // over before an ASan run's answer once).
  c.send("MOV 1 0.3\n");
  EXPECT_EQ(c.gcs("ONT? 1"), "1=0\n");  // the move was applied before the query is answered
  ASSERT_TRUE(TwinRig::wait_on_target(c, 5.0));
  EXPECT_NEAR(rig.x_mm(c), 0.3, 1e-3);  // within the 1 um on-target tolerance
  EXPECT_EQ(c.gcs("ERR?"), "0\n");
}

TEST(TwinServer, ADisconnectMidMoveLeavesTheStageHolding) {
  TwinRig rig;
  double stopped_mm = 0.0;
  {
    Client c(rig.gcs_port());
    rig.reference(c);
    c.send("VEL 1 0.1\nMOV 1 1\n");  // 10 s at 0.1 mm/s
    std::this_thread::sleep_for(300ms);
    stopped_mm = rig.x_mm(c);
    EXPECT_GT(stopped_mm, 0.01);
  }  // closed mid-move
  std::this_thread::sleep_for(300ms);
  Client watcher(rig.gcs_port());
  const double a = rig.x_mm(watcher);
  std::this_thread::sleep_for(500ms);
  const double b = rig.x_mm(watcher);
  EXPECT_LT(a - stopped_mm, 0.05);  // stopped at once: the disconnect releases the stage
  EXPECT_NEAR(a, b, 1e-3);          // and holds
}

TEST(TwinServer, TheEstopAndAConsoleUserInControlWin) {
  TwinRig rig;
  Client c(rig.gcs_port());
  rig.reference(c);
  rig.live->set_console_in_control(true);
  c.send("MOV 1 0.2\n");
  EXPECT_EQ(c.gcs("ERR?"), "10\n");
  rig.live->set_console_in_control(false);
  rig.live->estop();
  std::this_thread::sleep_for(50ms);
  c.send("MOV 1 0.2\n");
  EXPECT_EQ(c.gcs("ERR?"), "10\n");
  Client a(rig.anc_port());
  a.read_until([](const std::string& t) { return t.find("code: ") != std::string::npos; });
  a.send("123456\r\n");
  a.read_until([](const std::string& t) { return t.find("> ") != std::string::npos; });
  a.send("echo off\r\nsetm 1 stp\r\n");
  a.read_until([](const std::string& t) { return t.find("OK\r\nOK\r\n") != std::string::npos; });
  a.send("stepu 1 10\r\n");
  EXPECT_EQ(a.read_until([](const std::string& t) { return t.find("ERROR\r\n") != std::string::npos; }),
            "Platform halted (emergency stop latched)\r\nERROR\r\n");
}

TEST(TwinServer, AWrongAnc300PasswordIsRefusedAndClosed) {
  TwinRig rig;
  Client a(rig.anc_port());
  a.read_until([](const std::string& t) { return t.find("code: ") != std::string::npos; });
  for (int attempt = 0; attempt < 3; ++attempt) {
    a.send("letmein\r\n");
    EXPECT_NE(a.read_until([](const std::string& t) {
                 return t.find("failed\r\n") != std::string::npos;
               }).find("Authorization failed"),
              std::string::npos);
  }
  EXPECT_TRUE(a.closed_by_server());  // the third failure closes
}

// Step runs asked of two axes in one breath (one segment: within one tick of the loop) both play,
// as a controller plays its axes' runs at once: the protocol keeps a pending run per axis.
TEST(TwinServer, Anc300StepRunsAskedOfTwoAxesAtOnceBothPlay) {
  TwinRig rig;
  Client a(rig.anc_port());
  a.anc300_login();
  const auto oks = [&](int n) {
    const std::string t = a.read_until([n](const std::string& text) {
      int count = 0;
      for (auto at = text.find("OK\r\n"); at != std::string::npos; at = text.find("OK\r\n", at + 1)) ++count;
      return count >= n;
    });
    EXPECT_EQ(t.find("ERROR"), std::string::npos) << t;
  };
  a.send("setm 1 stp\r\nsetm 2 stp\r\nsetf 1 1000\r\nsetf 2 1000\r\nsetv 1 60\r\nsetv 2 60\r\n");
  oks(6);
  Client g(rig.gcs_port());
  const auto before = drivers::gcs2::parse_axis_values(g.gcs("POS? 1 2"));
  a.send("stepu 1 200\r\nstepu 2 200\r\n");
  oks(2);
  a.send("stepw 1\r\n");
  oks(1);
  a.send("stepw 2\r\n");
  oks(1);
  const auto after = drivers::gcs2::parse_axis_values(g.gcs("POS? 1 2"));
  // 200 periods of about 50 nm each (the model's step at 60 V, 1 kHz): micrometres, on both axes.
  for (std::size_t i = 0; i < 2; ++i)
    EXPECT_GT(after.at(i).second - before.at(i).second, 2e-3) << "axis " << i + 1 << " [mm]";
}

TEST(TwinServer, HostileClientsAreSurvived) {
  TwinRig rig(/*line_timeout_s=*/0.3);
  Client good(rig.gcs_port());
  {
    Client garbage(rig.gcs_port());
    std::string junk;
    for (int i = 0; i < 20000; ++i) junk += static_cast<char>((i * 131 + 17) % 256);
    garbage.send(junk + "\n");
  }
  std::this_thread::sleep_for(200ms);  // its lines are done (they set errors in the shared register)
  {
    Client slow(rig.gcs_port());
    slow.send("*ID");  // never finished
    EXPECT_TRUE(slow.closed_by_server());
  }
  {
    Client half(rig.gcs_port());
    half.send("CSV?\n");
    ::shutdown(half.fd, SHUT_WR);
    EXPECT_EQ(half.read_until([](const std::string&) { return false; }), "2.0\n");  // answered, then EOF
  }
  {
    Client deaf(rig.gcs_port());
    std::string flood;
    for (int i = 0; i < 20000; ++i) flood += "HLP?\n";  // replies it never reads
    deaf.send(flood);
    std::this_thread::sleep_for(300ms);
  }
  {
    std::vector<std::unique_ptr<Client>> many;
    for (int i = 0; i < 12; ++i) many.push_back(std::make_unique<Client>(rig.gcs_port(), 1.0));
    std::this_thread::sleep_for(100ms);
  }
  std::this_thread::sleep_for(100ms);
  EXPECT_EQ(good.gcs("CSV?"), "2.0\n");  // still served
  // The deaf client is closed once the server has answered enough of its flood to fill what it
  // will hold: under ASan on a loaded machine that may take longer than the test's own pauses (a
  // full sanitizer run failed this test once, not reproduced alone), so the counters are read
  // until they are in or 10 s have passed.
  auto counts = rig.server->counters();
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while ((counts.closed_hostile < 2 || counts.refused < 1) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(20ms);
    counts = rig.server->counters();
  }
  EXPECT_GE(counts.closed_hostile, 2u);  // the slowloris and the deaf client
  EXPECT_GE(counts.refused, 1u);         // beyond max_clients
}

// Apart from the slowloris rule's short timeout: a megabyte takes the server longer than 0.3 s to
// consume on a loaded machine under ASan, and the line would then be closed as never ending.
TEST(TwinServer, AHugeLineIsCappedItsRestDiscardedAndTheClientStillServed) {
  TwinRig rig;
  Client huge(rig.gcs_port());
  huge.send(std::string(1 << 20, 'A'));  // 1 MB without LF: capped, the rest discarded
  huge.send("\nERR?\n");
  EXPECT_EQ(huge.read_until([](const std::string& t) { return drivers::gcs2::reply_complete(t); }), "3\n");
  EXPECT_EQ(huge.gcs("CSV?"), "2.0\n");
  EXPECT_EQ(rig.server->counters().closed_hostile, 0u);
}

// A line whose rest the client sent in time but the protocol thread, starved of the CPU (a
// loaded machine, a sanitizer), has not read yet is not a slowloris: the slow one is the server.
TEST(TwinServer, ALineWhoseRestWaitsUnreadWhileTheServerIsStarvedIsAnswered) {
  testing::FakeStage fake;
  TwinServerParams tp;
  tp.endpoints = {{Protocol::kGcs2, "127.0.0.1", 0}};
  tp.line_timeout_s = 0.5;
  TwinServer server(fake, tp);
  server.start();
  Client c(server.ports()[0]);
  EXPECT_EQ(c.gcs("CSV?"), "2.0\n");
  c.send("ER");  // half a line, read by the server within a heartbeat
  std::this_thread::sleep_for(100ms);
  fake.stall_next_heartbeat_ms = 800;  // the protocol thread blocked past the line timeout
  std::this_thread::sleep_for(100ms);
  c.send("R?\n");  // the rest, in the kernel before the timeout
  EXPECT_EQ(c.read_until([](const std::string& t) { return drivers::gcs2::reply_complete(t); }), "0\n")
      << "closed as a slowloris";
  EXPECT_EQ(server.counters().closed_hostile, 0u);
  server.stop();
}

TEST(TwinServer, TheLoopThreadNeverAllocatesWhileProtocolClientsMoveTheStage) {
  TwinRig rig;
  Client gcs(rig.gcs_port());
  rig.reference(gcs);  // warm-up: every path touched once
  std::size_t allocations = 0;
  {
    test::AllocationGuard guard(rig.live->loop_thread_id());
    gcs.send("MOV 1 0.02 2 -0.02\n");
    ASSERT_TRUE(TwinRig::wait_on_target(gcs, 5.0));
    gcs.send("MOV 3 0.05\n");
    std::this_thread::sleep_for(20ms);
    gcs.send("HLT\n");
    EXPECT_EQ(gcs.gcs("ERR?"), "10\n");
    {
      Client a(rig.anc_port());
      a.read_until([](const std::string& t) { return t.find("code: ") != std::string::npos; });
      a.send("123456\r\necho off\r\nsetm 1 stp\r\nsetf 1 500\r\nsetv 1 60\r\n");
      a.read_until(
          [](const std::string& t) { return t.find("OK\r\nOK\r\nOK\r\nOK\r\n") != std::string::npos; });
      // gcs still holds control: the ANC300 client is refused; once gcs leaves, it steps.
      a.send("stepu 1 20\r\n");
      EXPECT_EQ(a.read_until([](const std::string& t) { return t.find("ERROR\r\n") != std::string::npos; }),
                "Another operator controls the stage\r\nERROR\r\n");
      ::shutdown(gcs.fd, SHUT_RDWR);
      std::this_thread::sleep_for(100ms);
      a.send("stepu 1 20\r\nstepw 1\r\n");
      EXPECT_EQ(
          a.read_until([](const std::string& t) { return t.find("OK\r\nOK\r\n") != std::string::npos; }),
          "OK\r\nOK\r\n");
    }  // leaves: the stage holds
    std::this_thread::sleep_for(50ms);
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
}

TEST(TwinServer, ParsesEmulateOptions) {
  EXPECT_EQ(parse_emulate("gcs2").port, 50000);
  EXPECT_EQ(parse_emulate("anc300").port, 7230);
  const auto e = parse_emulate("anc300=127.0.0.1:0");
  EXPECT_EQ(e.protocol, Protocol::kAnc300);
  EXPECT_EQ(e.port, 0);
  EXPECT_THROW(parse_emulate("smaract"), UsageError);
  EXPECT_THROW(parse_emulate("gcs2=1.2.3.4"), UsageError);
  // The MCS2 twin's channels without a sensor.
  const auto m = parse_emulate("mcs2=127.0.0.1:0,no_sensor=2+0");
  EXPECT_EQ(m.port, 0);
  EXPECT_EQ(m.no_sensor_channels, 0b101u);
  EXPECT_EQ(parse_emulate("mcs2,no_sensor=3").no_sensor_channels, 0b1000u);
  for (const char* bad : {"mcs2,no_sensor=4", "mcs2,no_sensor=", "mcs2,no_sensor=1+", "mcs2,sensor=1",
                          "gcs2,no_sensor=1", "mcs2=127.0.0.1:0,no_sensor=12"})
    EXPECT_THROW(parse_emulate(bad), UsageError) << bad;
  TwinServerParams p;
  p.endpoints = {{Protocol::kGcs2, "0.0.0.0", 0}};
  EXPECT_THROW(p.validate(), InvalidParams);  // off loopback without a token
  p.token = "0123456789abcdef";
  EXPECT_NO_THROW(p.validate());
}

}  // namespace
}  // namespace mc::twins
