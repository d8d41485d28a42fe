// The hexapod twin served over TCP (loopback, port 0) on the live platform's parallel positioner:
// the C-887 dialect's lines and single bytes through the server, hostile clients (garbage, an
// overlong line, half lines, a disconnect mid-move) survived with the platform holding, and the
// platform's loop thread never allocating while a client moves and stops the positioner.

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>

#include "fake_stage.h"
#include "hexapod_server_rig.h"
#include "microcobot/core/error.h"
#include "microcobot/drivers/gcs2_codec.h"
#include "support/counting_allocator.h"

namespace mc::twins {
namespace hexapod_server_test {

using namespace std::chrono_literals;
using testing::Client;

using testing::axis;
using testing::byte_reply;
using testing::HexapodServerRig;
using testing::reference;
using testing::wait_on_target;

TEST(HexapodServer, ParsesEmulateGcs2Hexapod) {
  EXPECT_EQ(parse_emulate("gcs2-hexapod").port, 50000);
  const auto e = parse_emulate("gcs2-hexapod=127.0.0.1:0");
  EXPECT_EQ(e.protocol, Protocol::kGcs2Hexapod);
  EXPECT_EQ(e.port, 0);
  EXPECT_STREQ(protocol_name(e.protocol), "gcs2-hexapod");
  EXPECT_THROW(parse_emulate("gcs2-hexapod=127.0.0.1"), UsageError);
  EXPECT_THROW(parse_emulate("hexapod"), UsageError);
  // Served only on a platform with the parallel positioner.
  testing::FakeStage cartesian;
  TwinServerParams tp;
  tp.endpoints = {{Protocol::kGcs2Hexapod, "127.0.0.1", 0}};
  EXPECT_THROW({ TwinServer server(cartesian, tp); }, InvalidParams);
}

TEST(HexapodServer, AClientReferencesMovesAndReadsThePoseOverTcp) {
  HexapodServerRig rig;
  Client c(rig.port(), 5.0);
  EXPECT_NE(c.gcs("*IDN?").find("C-887"), std::string::npos);
  EXPECT_EQ(byte_reply(c, 7), "\xb1\n");
  reference(c);
  // At 0.02 mm/s the move takes a second, so that #5 asked right after it reads every axis moving
  // even when the sanitizers slow the reply by a tenth of a second.
  c.send("VLS 0.02\nMOV X 0.02 Y -0.01 Z 0.01 U 0.1 V 0.1 W -0.1\n");
  EXPECT_EQ(byte_reply(c, 5), "3F\n");
  ASSERT_TRUE(wait_on_target(c));
  EXPECT_EQ(byte_reply(c, 5), "0\n");
  EXPECT_NEAR(axis(c, "POS? X"), 0.02, 1e-3);
  EXPECT_NEAR(axis(c, "POS? W"), -0.1, 1e-3);
  EXPECT_EQ(c.gcs("ERR?"), "0\n");
}

TEST(HexapodServer, HostileClientsAreSurvivedAndADisconnectMidMoveLeavesThePlatformHolding) {
  // A 2 s line timeout: the half line below is finished 0.1 s later, a margin a loaded machine under
  // the thread sanitizer keeps; the slowloris waits past it.
  HexapodServerRig rig(2.0);
  {
    Client garbage(rig.port(), 5.0);
    garbage.send("\x01\x02\xff\xfe garbage ;;; \x7f\n");
    garbage.send(std::string(3000, 'M') + "\n");  // overlong: error 3, its rest discarded
    EXPECT_EQ(garbage.gcs("ERR?"), "3\n");
    garbage.send("POS");  // half a line, finished later
    std::this_thread::sleep_for(100ms);
    EXPECT_EQ(garbage.gcs("? X").substr(0, 2), "X=");
  }
  {
    Client slow(rig.port(), 10.0);
    slow.send("POS? X");  // never finished: closed after the line timeout
    EXPECT_TRUE(slow.closed_by_server());
  }
  Client mover(rig.port(), 5.0);
  reference(mover);
  mover.send("MOV X 0.2\n");  // 2 s at 0.1 mm/s
  std::this_thread::sleep_for(400ms);
  ::shutdown(mover.fd, SHUT_RDWR);  // gone mid-move
  Client watcher(rig.port(), 5.0);
  ASSERT_TRUE(wait_on_target(watcher, 5.0));
  const double x = axis(watcher, "POS? X");
  EXPECT_GT(x, 0.005);
  EXPECT_LT(x, 0.19);
  std::this_thread::sleep_for(300ms);
  EXPECT_NEAR(axis(watcher, "POS? X"), x, 1e-3);  // holds
  EXPECT_NE(watcher.gcs("*IDN?").find("C-887"), std::string::npos);
  EXPECT_GE(rig.server->counters().closed_hostile, 1u);
}

TEST(HexapodServer, TheLoopThreadNeverAllocatesWhileAClientMovesAndStopsThePlatform) {
  HexapodServerRig rig;
  Client c(rig.port(), 5.0);
  reference(c);  // warm-up: the first move has made the trajectory's storage
  std::size_t allocations = 0;
  {
    test::AllocationGuard guard(rig.live->loop_thread_id());
    c.send("VLS 0.5\nMOV X 0.02 U 0.1\nMOV Y 0.02\n");
    ASSERT_TRUE(wait_on_target(c));
    c.send("MOV Z 0.1\n");
    std::this_thread::sleep_for(50ms);
    c.send(std::string(1, '\x18'));  // #24: no reply
    ASSERT_TRUE(wait_on_target(c, 5.0));
    EXPECT_EQ(c.gcs("ERR?"), "10\n");
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
}

}  // namespace hexapod_server_test
}  // namespace mc::twins
