// The live deployment built as a library object, without the command line: a single role on the
// skeleton driver bench (tests/platform/skeleton_drivers.h, so that the devices' safe state can be
// read from their "hardware") with the console and a GCS 2.0 twin on loopback port 0, answered
// through sockets and stopped with every device safe; a slave role on this test's own DDS domain;
// and configurations that fail with one clear error before anything is served.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "microcobot/core/error.h"
#include "microcobot/deployment/deployment.h"
#include "microcobot/platform/driver_registry.h"
#include "net/net_test_support.h"
#include "platform/skeleton_drivers.h"
#include "support/test_support.h"
#include "support/ws_client.h"

namespace mc::deployment {
namespace {

std::unique_ptr<test::SkeletonBench> g_deployment_bench;

const platform::DriverRegistration kDeploymentBench{
    "deployment-bench", [](const platform::PlatformConfig& config) {
      g_deployment_bench = std::make_unique<test::SkeletonBench>(config);
      return g_deployment_bench->devices();
    }};

// One line asked of a TCP server on loopback, its reply read up to the first newline (3 s at most).
std::string ask_line(std::uint16_t port, const std::string& line) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) throw std::runtime_error("socket");
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  timeval tv{3, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  std::string reply;
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 &&
      ::send(fd, line.data(), line.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(line.size())) {
    char buf[512];
    while (reply.find('\n') == std::string::npos) {
      const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
      if (n <= 0) break;
      reply.append(buf, static_cast<std::size_t>(n));
    }
  }
  ::close(fd);
  return reply;
}

// The lines a deployment logs, kept for the assertions.
struct LogLines {
  std::mutex mutex;
  std::vector<std::string> lines;
  Log sink() {
    return [this](const std::string& line) {
      std::lock_guard lock(mutex);
      lines.push_back(line);
    };
  }
  bool has(const std::string& text) {
    std::lock_guard lock(mutex);
    for (const std::string& l : lines)
      if (l.find(text) != std::string::npos) return true;
    return false;
  }
};

TEST(Deployment, ASingleRoleServesTheConsoleAndATwinThenStopsWithEveryDeviceSafe) {
  test::TempDir dir;
  ServeConfig config;
  config.platform.devices.driver = "deployment-bench";
  config.listen_port = 0;
  config.out = dir / "live";
  config.record = true;
  config.twins = {{twins::Protocol::kGcs2, "127.0.0.1", 0}};
  LogLines log;
  Deployment deployment(config, log.sink());
  ASSERT_TRUE(g_deployment_bench) << "the configured driver set was built";
  EXPECT_TRUE(log.has("building the platform")) << "on the drivers 'deployment-bench'";
  EXPECT_TRUE(log.has("'deployment-bench'"));
  EXPECT_FALSE(log.has("parallel positioner")) << "none configured";
  EXPECT_TRUE(deployment.config().token.empty()) << "on loopback no token is drawn";

  deployment.start();
  const std::uint16_t port = deployment.port();
  ASSERT_NE(port, 0);
  EXPECT_EQ(deployment.url(), "http://127.0.0.1:" + std::to_string(port) + "/");
  EXPECT_EQ(test::http_request(port, "GET", "/").status, 200) << "the console's page";

  const std::vector<ServedTwin> served = deployment.twins();
  ASSERT_EQ(served.size(), 1u);
  EXPECT_EQ(served[0].name, "gcs2");
  EXPECT_EQ(served[0].address, "127.0.0.1");
  EXPECT_FALSE(served[0].token_required);
  ASSERT_NE(served[0].port, 0);
  EXPECT_EQ(ask_line(served[0].port, "*IDN?\n").rfind("microcobot, E-873 digital twin, 0, ", 0), 0u);

  EXPECT_FALSE(deployment.port_energy()) << "no master-slave channel in the single role";
  ASSERT_TRUE(test::eventually([&] {
    for (const auto& b : g_deployment_bench->buses)
      if (!b.powered) return false;
    return true;
  })) << "the loop activated the axes";

  deployment.stop();
  for (const auto& b : g_deployment_bench->buses) EXPECT_FALSE(b.powered) << "every axis in its safe state";
  bool recorded = false;
  for (const auto& e : std::filesystem::directory_iterator(dir / "live"))
    recorded = recorded || e.path().extension() == ".mcap";
  EXPECT_TRUE(recorded) << "the recording started with the deployment and closed with it";
  deployment.stop();  // idempotent
}

TEST(Deployment, ASlaveRoleJoinsItsDomainAndReportsItsPorts) {
  test::TempDir dir;
  ServeConfig config;
  config.listen_port = 0;
  config.out = dir / "live";
  config.role = Role::kSlave;
  config.domain = net::test::test_domain_id();
  LogLines log;
  Deployment deployment(config, log.sink());
  EXPECT_TRUE(log.has("slave of a distributed platform on DDS domain " + std::to_string(config.domain) +
                      " (loopback; the peer: serve --role master"));
  if (deployment.live().has_camera()) {
    EXPECT_TRUE(log.has("the microscope's focus and objective on DDS"));
    EXPECT_TRUE(log.has("camera images on DDS"));
  }
  deployment.start();
  EXPECT_EQ(test::http_request(deployment.port(), "GET", "/").status, 200);
  ASSERT_TRUE(deployment.port_energy());
  deployment.stop();
}

TEST(Deployment, TheStartLineSaysWhatRunsTheParallelPositioner) {
  test::TempDir dir;
  ServeConfig config;
  config.listen_port = 0;
  config.out = dir / "live";
  config.platform.positioner = "parallel";
  LogLines log;
  Deployment deployment(config, log.sink());
  EXPECT_TRUE(
      log.has("on the simulated devices, the parallel positioner simulated (its legs on their controller's "
              "thread)"));
}

TEST(Deployment, ABadConfigurationFailsWithOneClearErrorBeforeAnythingIsServed) {
  test::TempDir dir;
  test::write_text(dir / "a-file", "x");
  using Change = std::function<void(ServeConfig&)>;
  const struct {
    std::string name;
    Change change;
    int exit_code;
    std::string message;
  } cases[] = {
      {"unknown scene", [](ServeConfig& c) { c.scene = "pin-in-hol"; }, 3,
       "--scene 'pin-in-hol': neither a built-in scene (pick-place, pin-in-hole, optical-trap) nor a scene "
       "file"},
      {"cell field without cell", [](ServeConfig& c) { c.seed = 3; }, 2, "--seed: needs --cell"},
      {"link without role", [](ServeConfig& c) { c.link.delay_s = 0.05; }, 2,
       "--link-delay, --link-jitter, --link-loss: need --role master or slave"},
      {"short token", [](ServeConfig& c) { c.token = "short"; }, 2, "--token: must be 8 to 256"},
      {"out is a file", [&](ServeConfig& c) { c.out = dir / "a-file"; }, 3,
       "cannot create --out " + (dir / "a-file").string()},
      {"unknown driver", [](ServeConfig& c) { c.platform.devices.driver = "smaract"; }, 3,
       "devices.driver: 'smaract' is not a registered driver"},
      {"domain out of range",
       [](ServeConfig& c) {
         c.role = Role::kMaster;
         c.domain = 231;
       },
       2, "--domain: 231 is out of range"},
  };
  for (const auto& c : cases) {
    ServeConfig config;
    config.listen_port = 0;
    config.out = dir / "live";
    c.change(config);
    LogLines log;
    try {
      Deployment d(config, log.sink());
      ADD_FAILURE() << c.name << ": built";
    } catch (const Error& e) {
      EXPECT_EQ(static_cast<int>(e.exit_code()), c.exit_code) << c.name << ": " << e.what();
      EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos) << c.name << ": " << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "one line";
    }
    EXPECT_FALSE(log.has("building the platform")) << c.name << ": refused before the platform was built";
  }
}

}  // namespace
}  // namespace mc::deployment
