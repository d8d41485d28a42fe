// The MCS2 twin served on the live platform (paced loop, loopback, port 0): the channel state
// bits through a reference and a move, the golden transcripts of tests/data/mcs2 (the EPICS
// motorSmarAct driver's sequences; kamzik3's, each command followed by `:SYST:ERR:NEXT?`) replayed
// with their replies checked, and hostile clients (garbage, an overlong line, half lines, a
// disconnect mid-move) survived with the axes holding.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <regex>
#include <string>
#include <thread>

#include "microcobot/core/error.h"
#include "microcobot/drivers/mcs2_codec.h"
#include "support/counting_allocator.h"
#include "twin_rig.h"

namespace mc::twins {
namespace {

using namespace std::chrono_literals;
using testing::Client;
namespace bit = drivers::mcs2::channel_state;

/// The live platform with the MCS2 twin alone on loopback port 0.
struct Mcs2LiveRig {
  live::LiveParams params = testing::twin_live_params();
  std::unique_ptr<live::LivePlatform> live;
  std::unique_ptr<LiveStage> stage;
  std::unique_ptr<TwinServer> server;
  explicit Mcs2LiveRig(double line_timeout_s = 5.0) {
    live = std::make_unique<live::LivePlatform>(params);
    live->start([](const platform::TelemetrySample&, std::size_t) {});
    stage = std::make_unique<LiveStage>(*live);
    TwinServerParams tp;
    tp.endpoints = {{Protocol::kMcs2, "127.0.0.1", 0}};
    tp.line_timeout_s = line_timeout_s;
    tp.max_clients = 8;
    tp.mcs2.calibration_s = 0.1;
    server = std::make_unique<TwinServer>(*stage, tp);
    server->start();
  }
  ~Mcs2LiveRig() {
    server->stop();
    live->stop();
  }
  std::uint16_t port() const { return server->ports()[0]; }
};

/// One CR LF line from the client (without its CR LF); empty on a timeout.
std::string read_line(const Client& c, std::string& buffer) {
  while (buffer.find('\n') == std::string::npos) {
    char chunk[4096];
    const ssize_t n = ::recv(c.fd, chunk, sizeof chunk, 0);
    if (n <= 0) return "<timeout>";
    buffer.append(chunk, static_cast<std::size_t>(n));
  }
  const std::size_t lf = buffer.find('\n');
  std::string line = buffer.substr(0, lf);
  buffer.erase(0, lf + 1);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return line;
}

struct Mcs2Client {
  Client c;
  std::string buffer;
  explicit Mcs2Client(std::uint16_t port) : c(port) {}
  void send(const std::string& line) { c.send(line + "\r\n"); }
  std::string line() { return read_line(c, buffer); }
  std::string ask(const std::string& line) {
    send(line);
    return this->line();
  }
  std::uint32_t stat(int n) {
    return static_cast<std::uint32_t>(std::stoul(ask(fmt::format(":CHAN{}:STAT?", n))));
  }
  bool wait_state(int n, std::uint32_t mask, std::uint32_t value, double timeout_s = 10.0) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < end) {
      if ((stat(n) & mask) == value) return true;
      std::this_thread::sleep_for(10ms);
    }
    return false;
  }
};

/// A reply matches `pattern`: a regular expression matched whole, or `&MASK=VALUE` (hex).
bool matches(const std::string& pattern, const std::string& got) {
  if (!pattern.empty() && pattern[0] == '&') {
    const std::size_t eq = pattern.find('=');
    const auto mask = std::stoull(pattern.substr(1, eq - 1), nullptr, 16);
    const auto value = std::stoull(pattern.substr(eq + 1), nullptr, 16);
    const auto v = drivers::mcs2::parse_integer(got);
    return v && (static_cast<std::uint64_t>(*v) & mask) == value;
  }
  return std::regex_match(got, std::regex(pattern));
}

/// Plays a transcript (syntax in tests/data/mcs2/epics_motorsmaract.txt's header); a line
/// `#! append LINE` sends LINE after each command, as kamzik3 does.
void replay(const std::string& name, std::uint16_t port) {
  std::ifstream in(std::string(MC_TEST_DATA_DIR) + "/mcs2/" + name);
  ASSERT_TRUE(in) << name;
  Mcs2Client c(port);
  std::string append, raw;
  int n = 0;
  while (std::getline(in, raw)) {
    ++n;
    const std::string where = name + ":" + std::to_string(n) + ": " + raw;
    if (raw.rfind("#! append ", 0) == 0) append = raw.substr(10);
    if (raw.empty() || raw[0] == '#') continue;
    const std::string text = raw.substr(2);
    if (raw[0] == '>') {
      c.send(text);
      if (!append.empty()) c.send(append);
    } else if (raw[0] == '<') {
      const std::string got = c.line();
      ASSERT_TRUE(matches(text, got)) << where << "\n  got: " << got;
    } else if (raw[0] == '~') {
      const std::size_t arrow = text.find(" => ");
      const std::string query = text.substr(0, arrow), pattern = text.substr(arrow + 4);
      const auto end = std::chrono::steady_clock::now() + 10s;
      for (;;) {
        c.send(query);
        if (!append.empty()) c.send(append);
        const std::string got = c.line();
        if (matches(pattern, got)) break;
        ASSERT_LT(std::chrono::steady_clock::now(), end) << where << "\n  last: " << got;
        if (!append.empty()) {
          EXPECT_EQ(c.line(), "0,\"No error\"") << where;
        }
        std::this_thread::sleep_for(20ms);
      }
    } else {
      FAIL() << where << ": bad line";
    }
  }
  // Nothing left unread: every reply was written in the transcript.
  EXPECT_EQ(c.ask(":SYST:ERR:COUN?"), "0") << name;
}

TEST(Mcs2Server, TheEpicsMotorSmarActTranscriptIsAnsweredAsWritten) {
  Mcs2LiveRig rig;
  replay("epics_motorsmaract.txt", rig.port());
}

TEST(Mcs2Server, AKamzik3ClientAppendingSystErrNextGetsOneReplyMoreForEachCommand) {
  Mcs2LiveRig rig;
  replay("kamzik3.txt", rig.port());
}

TEST(Mcs2Server, StateBitsDuringAMoveAndAfterTheReference) {
  Mcs2LiveRig rig;
  Mcs2Client c(rig.port());
  EXPECT_EQ(c.stat(0) & (bit::kIsReferenced | bit::kSensorPresent), bit::kSensorPresent);
  c.send(":CHAN0:HOLD -1;:CHAN0:VEL 1000000000;:REF0");
  ASSERT_TRUE(c.wait_state(0, bit::kIsReferenced | bit::kActivelyMoving, bit::kIsReferenced));
  EXPECT_EQ(c.stat(0), bit::kClosedLoopActive | bit::kSensorPresent | bit::kIsReferenced |
                           bit::kAmplifierEnabled | bit::kInPosition);
  // 0.3 mm at 1 mm/s: the query right after finds it moving in closed loop, not in position.
  c.send(":MOVE0 300000000");
  const auto during = c.stat(0);
  EXPECT_EQ(during & (bit::kActivelyMoving | bit::kClosedLoopActive | bit::kInPosition),
            bit::kActivelyMoving | bit::kClosedLoopActive);
  ASSERT_TRUE(c.wait_state(0, bit::kActivelyMoving | bit::kInPosition, bit::kInPosition));
  EXPECT_NEAR(std::stoll(c.ask(":CHAN0:POS?")), 300'000'000, 1'000'000);  // within 1 um
  EXPECT_EQ(c.ask(":SYST:ERR:COUN?"), "0");
}

TEST(Mcs2Server, HostileClientsAreSurvivedAndADisconnectMidMoveLeavesTheAxesHolding) {
  Mcs2LiveRig rig(/*line_timeout_s=*/0.3);
  Mcs2Client good(rig.port());
  {
    Client garbage(rig.port());
    std::string junk;
    for (int i = 0; i < 20000; ++i) junk += static_cast<char>((i * 131 + 17) % 256);
    garbage.send(junk + "\r\n");
  }
  {
    Client overlong(rig.port());
    overlong.send(std::string(100000, ':') + "\r\n");  // capped, its rest discarded: error -363
  }
  {
    Client half(rig.port());
    half.send(":CHAN0:ST");  // never finished: closed as a slowloris
    EXPECT_TRUE(half.closed_by_server());
  }
  {
    Client half_closed(rig.port());
    half_closed.send(":DEV:NOCH?\r\n:CHAN0:STAT");  // a whole line answered, the half line dropped
    ::shutdown(half_closed.fd, SHUT_WR);
    EXPECT_EQ(half_closed.read_until([](const std::string&) { return false; }), "4\r\n");
  }
  std::this_thread::sleep_for(100ms);
  good.ask("*CLS;:DEV:NOCH?");
  double stopped_pm = 0;
  {
    Mcs2Client mover(rig.port());
    mover.send(":CHAN0:VEL 1000000000;:REF0");
    ASSERT_TRUE(mover.wait_state(0, bit::kIsReferenced | bit::kActivelyMoving, bit::kIsReferenced));
    mover.send(":CHAN0:VEL 100000000;:MOVE0 1000000000");  // 10 s at 0.1 mm/s
    std::this_thread::sleep_for(300ms);
    stopped_pm = static_cast<double>(std::stoll(mover.ask(":CHAN0:POS?")));
    EXPECT_GT(stopped_pm, 1e7);
  }  // gone mid-move
  std::this_thread::sleep_for(300ms);
  const double a = static_cast<double>(std::stoll(good.ask(":CHAN0:POS?")));
  std::this_thread::sleep_for(500ms);
  const double b = static_cast<double>(std::stoll(good.ask(":CHAN0:POS?")));
  EXPECT_LT(a - stopped_pm, 5e7);  // stopped at once: the disconnect releases the stage
  EXPECT_NEAR(a, b, 1e6);          // and holds
  // The channel says so: not moving, no target held, the move failed.
  EXPECT_EQ(good.stat(0) & (bit::kActivelyMoving | bit::kClosedLoopActive | bit::kMovementFailed),
            bit::kMovementFailed);
  EXPECT_EQ(good.ask(":DEV:NOBM?"), "2");  // still served
  EXPECT_GE(rig.server->counters().closed_hostile, 1u);
}

TEST(Mcs2Server, TheLoopThreadNeverAllocatesWhileAnMcs2ClientMovesStepsAndStopsTheStage) {
  Mcs2LiveRig rig;
  Mcs2Client c(rig.port());
  c.send(":CHAN0:HOLD -1;:CHAN0:VEL 1000000000;:CHAN1:VEL 1000000000;:REF0");  // warm-up
  ASSERT_TRUE(c.wait_state(0, bit::kIsReferenced | bit::kActivelyMoving, bit::kIsReferenced));
  std::size_t allocations = 0;
  {
    test::AllocationGuard guard(rig.live->loop_thread_id());
    c.send(":MOVE0 20000000;:CHAN1:MMOD 1;:MOVE1 -20000000");
    ASSERT_TRUE(c.wait_state(0, bit::kActivelyMoving, 0));
    ASSERT_TRUE(c.wait_state(1, bit::kActivelyMoving, 0));
    c.send(":CHAN2:MMOD 4;:MOVE2 50");
    ASSERT_TRUE(c.wait_state(2, bit::kActivelyMoving, 0));
    c.send(":MOVE0 50000000");
    std::this_thread::sleep_for(20ms);
    c.send(":STOP0");
    ASSERT_TRUE(c.wait_state(0, bit::kActivelyMoving, 0));
    EXPECT_EQ(c.ask(":SYST:ERR:COUN?"), "0");
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
}

TEST(Mcs2Server, AnOverlongLineIsError363) {
  Mcs2LiveRig rig;
  Mcs2Client c(rig.port());
  c.send(std::string(4096, 'A'));
  EXPECT_EQ(c.ask(":SYST:ERR:NEXT?"), "-363,\"Input buffer overrun\"");
  EXPECT_EQ(c.ask(":SYST:ERR:NEXT?"), "0,\"No error\"");
}

TEST(Mcs2Server, ParsesEmulateMcs2) {
  EXPECT_EQ(parse_emulate("mcs2").port, 55551);
  const auto e = parse_emulate("mcs2=127.0.0.1:0");
  EXPECT_EQ(e.protocol, Protocol::kMcs2);
  EXPECT_EQ(e.port, 0);
  EXPECT_STREQ(protocol_name(e.protocol), "mcs2");
  EXPECT_THROW(parse_emulate("mcs2=127.0.0.1"), UsageError);
  EXPECT_THROW(parse_emulate("smaract"), UsageError);
}

}  // namespace
}  // namespace mc::twins
