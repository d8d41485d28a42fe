// The `pi-hexapod` driver's configuration and its configure-time refusals, against a scriptable
// controller in this process (loopback, port 0): the configuration selects it under
// `parallel_positioner:` (the simulated positioner stays the default), its connection's options
// are checked naming the key, and a controller that is not a C-887 (garbage, or another PI
// controller's *IDN?) fails the platform's construction in one line naming what it answered.

#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include <fmt/format.h>

#include "drivers/fake_controller.h"
#include "microcobot/core/error.h"
#include "microcobot/core/params.h"
#include "microcobot/drivers/pi_hexapod.h"
#include "microcobot/drivers/register_drivers.h"
#include "microcobot/platform/driver_registry.h"
#include "support/test_support.h"

namespace mc::drivers {
namespace pi_hexapod_driver_test {

using Clock = std::chrono::steady_clock;
using platform::PlatformConfig;

PlatformConfig hexapod_config(const std::string& connection) {
  register_vendor_drivers();
  PlatformConfig c;
  c.positioner = "parallel";
  c.parallel_positioner.driver = "pi-hexapod";
  c.parallel_positioner.connection = connection;
  return c;
}

// The platform's construction error (configure runs there), or "" when it was built.
std::string construction_error(const PlatformConfig& c) {
  try {
    platform::make_platform(c);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(PiHexapodDriver, TheConfigurationSelectsItUnderParallelPositionerAndKeepsTheSimulatedDefault) {
  register_vendor_drivers();
  EXPECT_EQ(PlatformConfig{}.parallel_positioner.driver, "simulated");
  const auto names = platform::positioner_driver_names();
  EXPECT_EQ(names, (std::vector<std::string>{"simulated", "pi-hexapod"}));
  // The YAML keys, read as any other.
  test::TempDir dir;
  test::write_text(dir / "p.yaml",
                   "positioner: parallel\nparallel_positioner: {driver: pi-hexapod, connection: "
                   "\"127.0.0.1:50000,timeout_s=0.2\"}\n");
  const PlatformConfig c = platform::load_platform_config(dir / "p.yaml");
  EXPECT_EQ(c.parallel_positioner.driver, "pi-hexapod");
  EXPECT_EQ(c.parallel_positioner.connection, "127.0.0.1:50000,timeout_s=0.2");
  EXPECT_EQ(c.parallel_positioner.move.max_speed_m_s, motion::PoseMoveLimits{}.max_speed_m_s);
  // An unknown driver: one line naming the key and the known ones.
  test::write_text(dir / "bad.yaml", "parallel_positioner: {driver: smarpod}\n");
  try {
    platform::load_platform_config(dir / "bad.yaml");
    ADD_FAILURE() << "accepted driver: smarpod";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("parallel_positioner.driver"), std::string::npos) << what;
    EXPECT_NE(what.find("'smarpod' is not a registered positioner driver (known: simulated, pi-hexapod)"),
              std::string::npos)
        << what;
  }
}

TEST(PiHexapodDriver, ItsConnectionIsHostPortAndOptionsEachCheckedNamingTheKey) {
  const PiHexapodParams p =
      pi_hexapod_params(parse_connection("h:1,timeout_s=0.3,stale_s=0.4,reference=0", "x"));
  EXPECT_DOUBLE_EQ(p.timing.reply_timeout_s, 0.3);
  EXPECT_DOUBLE_EQ(p.timing.stale_timeout_s, 0.4);
  EXPECT_FALSE(p.reference);
  EXPECT_DOUBLE_EQ(PiHexapodParams{}.timing.poll_period_s, 0.005);
  for (const auto& [connection, expected] : std::vector<std::pair<std::string, std::string>>{
           {"127.0.0.1",
            "parallel_positioner.connection: '127.0.0.1': the pi-hexapod driver needs HOST:PORT"},
           {"127.0.0.1:1,speed=3",
            "parallel_positioner.connection: unknown option 'speed' (known: timeout_s"},
           {"127.0.0.1:1,timeout_s=-1", "parallel_positioner.connection option timeout_s: '-1' must be"},
           {"/dev/ttyUSB0",
            "parallel_positioner.connection: '/dev/ttyUSB0': the pi-hexapod driver connects over TCP"}}) {
    const std::string what = construction_error(hexapod_config(connection));
    EXPECT_NE(what.find(expected), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

// A controller that answers *IDN? with `idn` (and closes on anything else).
std::string configure_error_against(const std::string& idn) {
  test::FakeController fake([&](const std::string& line) -> test::FakeController::Answer {
    if (line == "*IDN?") return {idn};
    return {"", true};
  });
  const auto start = Clock::now();
  const std::string what =
      construction_error(hexapod_config(fmt::format("127.0.0.1:{},connect_timeout_s=0.3", fake.port())));
  // Nothing hangs: refused within the connect timeout (the first reply's).
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - start).count(), 2.0);
  EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  EXPECT_NE(what.find(fmt::format("pi-hexapod controller at 127.0.0.1:{}", fake.port())), std::string::npos)
      << what;
  return what;
}

TEST(PiHexapodDriver, AControllerThatIsNotAC887IsRefusedInOneLineNamingWhatItAnswered) {
  // Another PI controller.
  std::string what = configure_error_against("(c)2026 Physik Instrumente (PI), E-873.1AT, 0, 1.2\n");
  EXPECT_NE(what.find("*IDN? reads '(c)2026 Physik Instrumente (PI), E-873.1AT, 0, 1.2': not a PI C-887 "
                      "hexapod controller"),
            std::string::npos)
      << what;
  // Garbage, ended by a line feed.
  what = configure_error_against("@@\x7f garbage ##\n");
  EXPECT_NE(what.find("garbage ##': not a PI C-887"), std::string::npos) << what;
  // Garbage that never ends a line: the reply timeout, naming what came.
  what = configure_error_against("\x13\x37 binary noise");
  EXPECT_NE(what.find("'*IDN?': no reply within the timeout (got '"), std::string::npos) << what;
  EXPECT_NE(what.find("binary noise"), std::string::npos) << what;
  // Nothing listens: the address.
  const std::string closed = construction_error(hexapod_config("127.0.0.1:1"));
  EXPECT_NE(closed.find("cannot connect to the controller at 127.0.0.1:1"), std::string::npos) << closed;
}

}  // namespace pi_hexapod_driver_test
}  // namespace mc::drivers
