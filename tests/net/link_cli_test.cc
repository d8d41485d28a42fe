// `microcobot link echo` and `link ping` as a user runs them: two processes over DDS on loopback,
// on a domain id of this test process.

#include <signal.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "net/net_test_support.h"
#include "support/test_support.h"

namespace mc {
namespace {

using namespace std::chrono_literals;
using mc::test::run_cli;
using mc::test::TempDir;
using ::testing::HasSubstr;

TEST(LinkCli, PingThroughAnEchoProcessOverLoopback) {
  TempDir dir;
  const std::string domain = std::to_string(net::test::test_domain_id());
  // --duration: a safety net should the test die before it signals the echo.
  // The echo names its interface and peer as on two machines (here both loopback); the ping
  // keeps the default: the same configuration.
  const test::BackgroundCli echo =
      test::spawn_cli({"link", "echo", "--domain", domain, "--json", "--duration", "120", "--interface",
                       "127.0.0.1", "--peer", "127.0.0.1"},
                      dir / "echo");
  const auto ping = run_cli({"link", "ping", "--domain", domain, "--count", "2000", "--estop", "--json"});
  ASSERT_EQ(ping.exit_code, 0) << ping.err;
  const auto p = nlohmann::json::parse(ping.out);
  EXPECT_EQ(p["sent"], 2000);
  // Best effort, keep last 1: when a starved process (a loaded 2-core machine under ctest -j2)
  // is not scheduled for a period, the newer target overwrites the older one; measured 3-17 % lost
  // at a load average of 5, 59-62 % inside ctest -j2 (docs/benchmarks.md). Echoes must come back,
  // not all of them, and in bounded time; how fast is bench/link_bench.mjs's business (a CI run
  // measured p99 65 ms beside two real-time loops), not this test's.
  EXPECT_GE(p["received"].get<int>(), 100) << ping.out;
  EXPECT_LT(p["rtt_max_s"].get<double>(), 1.0) << ping.out;
  EXPECT_LE(p["rtt_p50_s"].get<double>(), p["rtt_p99_s"].get<double>());
  EXPECT_EQ(p["rejected"], 0);
  EXPECT_EQ(p["unexpected"], 0);
  EXPECT_TRUE(p["estop_acknowledged"].get<bool>()) << ping.out;

  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  ::kill(echo.pid, SIGTERM);
  ASSERT_EQ(test::wait_process(echo.pid, 10s), 0) << test::read_text(echo.err);
  const auto e = nlohmann::json::parse(test::read_text(echo.out));
  EXPECT_TRUE(e["estop_received"].get<bool>()) << e.dump();
  EXPECT_TRUE(e["estop"].get<bool>());
  EXPECT_GE(e["echoed"].get<int>(), p["received"].get<int>());
  EXPECT_EQ(e["rejected"], 0);
  EXPECT_TRUE(e["liveliness_lost"].is_number_unsigned()) << e.dump();
  EXPECT_EQ(e["stopped_by"], "SIGTERM");
}

TEST(LinkCli, PingWithoutAPeerFailsWithOneLine) {
  // A domain no echo listens on (this test's own, with a short wait).
  const auto r = run_cli({"link", "ping", "--domain", std::to_string(net::test::test_domain_id()), "--wait",
                          "0.5", "--count", "10"});
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_THAT(r.err, HasSubstr("no peer on DDS domain"));
  EXPECT_EQ(test::line_count(r.err), 1u) << r.err;
}

TEST(LinkCli, AnInterfaceThisMachineLacksIsOneLineWithCyclonesReason) {
  const auto r = run_cli({"link", "echo", "--domain", std::to_string(net::test::test_domain_id()),
                          "--interface", "mcnosuch0", "--duration", "1"});
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_EQ(test::line_count(r.err), 1u) << r.err;
  EXPECT_THAT(r.err, HasSubstr("interface 'mcnosuch0': mcnosuch0: does not match an available interface"));
}

TEST(LinkCli, BadFlagsAreUsageErrorsNamingTheFlag) {
  for (const auto& args : std::vector<std::vector<std::string>>{{"link", "ping", "--domain", "231"},
                                                                {"link", "ping", "--domain", "x"},
                                                                {"link", "echo", "--domain", "-1"}}) {
    const auto r = run_cli(args);
    EXPECT_EQ(r.exit_code, 2) << args[3];
    EXPECT_THAT(r.err, HasSubstr("--domain"));
    EXPECT_EQ(test::line_count(r.err), 1u) << r.err;
  }
  for (const auto& [flag, value] :
       std::vector<std::pair<std::string, std::string>>{{"--count", "0"},
                                                        {"--rate", "nan"},
                                                        {"--rate", "0"},
                                                        {"--wait", "-1"},
                                                        {"--interface", "eth0;rm"},
                                                        {"--peer", ""}}) {
    const auto r = run_cli({"link", "ping", flag, value});
    EXPECT_EQ(r.exit_code, 2) << flag;
    EXPECT_THAT(r.err, HasSubstr(flag));
  }
  const auto r = run_cli({"link"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("echo"));
}

}  // namespace
}  // namespace mc
