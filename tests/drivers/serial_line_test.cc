// The vendor drivers' serial transport against a pseudo-terminal standing in for the
// serial line (no USB adapter is involved): the line is opened raw, 8N1, at the configured baud,
// without flow control unless asked; every read has its deadline; the pi-gcs2 driver configures
// the platform and moves its axes over the line without allocating in the loop; a path that does
// not exist and a file that is not a tty are refused in one line (exit 3); unplugging the line
// (closing the master) puts the platform in its safe state within one reply timeout; the anc300
// driver steps over the line without the telnet console's password.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>

#include "drivers/fake_controller.h"
#include "drivers/gcs2_test_rig.h"
#include "microcobot/core/error.h"
#include "microcobot/drivers/anc300_driver.h"
#include "microcobot/drivers/gcs2_driver.h"
#include "microcobot/drivers/line_client.h"
#include "microcobot/drivers/register_drivers.h"
#include "microcobot/platform/driver_registry.h"
#include "support/counting_allocator.h"
#include "support/sanitizers.h"
#include "support/test_support.h"

namespace mc::drivers {
namespace serial_line_test {

using namespace std::chrono_literals;
using namespace gcs2_test_rig;

// A pseudo-terminal owned by the test: the master kept here, the slave's path for the client.
struct Pty {
  int master = -1;
  std::string slave;
  Pty() {
    master = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
    char name[128] = {};
    if (master < 0 || ::grantpt(master) != 0 || ::unlockpt(master) != 0 ||
        ::ptsname_r(master, name, sizeof name) != 0)
      throw std::runtime_error("no pseudo-terminal");
    slave = name;
  }
  ~Pty() { unplug(); }
  void unplug() {
    if (master >= 0) ::close(master);
    master = -1;
  }
  // The slave's settings (a pty master's termios calls act on its slave).
  termios settings() const {
    termios t{};
    ::tcgetattr(master, &t);
    return t;
  }
  std::string read_master(std::size_t n) const {
    std::string got;
    const auto until = Clock::now() + 1s;
    while (got.size() < n && Clock::now() < until) {
      char buf[256];
      const ssize_t k = ::read(master, buf, sizeof buf);
      if (k > 0) got.append(buf, static_cast<std::size_t>(k));
    }
    return got;
  }
};

PlatformConfig serial_gcs2_config(const std::string& connection) {
  register_vendor_drivers();
  PlatformConfig c;
  c.devices.driver = "pi-gcs2";
  c.devices.connection = connection;
  return c;
}

std::size_t line_end(const std::string& t) {
  const auto eol = t.find('\n');
  return eol == std::string::npos ? 0 : eol + 1;
}

TEST(SerialLine, TheConnectionIsADevicePathWithItsBaudAndFlowTheDriverNeverSees) {
  const Connection g = parse_connection("/dev/ttyUSB0,timeout_s=0.2", "pi-gcs2", kGcs2DefaultBaud);
  EXPECT_TRUE(g.is_serial());
  EXPECT_EQ(g.serial.path, "/dev/ttyUSB0");
  EXPECT_EQ(g.serial.baud, 115200);
  EXPECT_FALSE(g.serial.rtscts);
  EXPECT_EQ(g.where(), "/dev/ttyUSB0");
  EXPECT_DOUBLE_EQ(gcs2_driver_params(g).timing.reply_timeout_s, 0.2);
  const Connection a = parse_connection("/dev/ttyACM0", "anc300", kAnc300DefaultBaud);
  EXPECT_EQ(a.serial.baud, 38400);
  const Connection b = parse_connection("/dev/ttyS0,baud=9600,flow=rtscts,password=x", "anc300", 38400);
  EXPECT_EQ(b.serial.baud, 9600);
  EXPECT_TRUE(b.serial.rtscts);
  EXPECT_EQ(b.options.count("baud"), 0u);  // taken by the line: the driver's option check passes
  EXPECT_EQ(anc300_driver_params(b).password, "x");
  EXPECT_FALSE(parse_connection("127.0.0.1:50000", "pi-gcs2").is_serial());
  for (const char* bad : {"/dev/ttyUSB0,baud=12345", "/dev/ttyUSB0,baud=fast", "/dev/ttyUSB0,flow=xonxoff",
                          "/dev/ttyUSB0,baud=9600,baud=9600", "127.0.0.1:50000,baud=9600", "h:1,flow=none",
                          "dev/ttyUSB0", "COM3"})
    EXPECT_THROW(parse_connection(bad, "pi-gcs2"), InvalidParams) << bad;
  try {
    parse_connection("/dev/ttyUSB0,baud=12345", "pi-gcs2");
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("'12345' must be one of 1200"), std::string::npos) << e.what();
  }
}

TEST(SerialLine, OpensTheLineRawAt8N1WithoutFlowControlAndKeepsEveryByte) {
  Pty pty;
  LineClient client;
  client.open(parse_connection(pty.slave, "pi-gcs2", kGcs2DefaultBaud), 1.0);
  ASSERT_TRUE(client.is_open());
  termios t = pty.settings();
  EXPECT_EQ(::cfgetospeed(&t), B115200);
  EXPECT_EQ(::cfgetispeed(&t), B115200);
  EXPECT_EQ(t.c_cflag & CSIZE, static_cast<tcflag_t>(CS8));
  EXPECT_EQ(t.c_cflag & (PARENB | CSTOPB | CRTSCTS), 0u);
  EXPECT_NE(t.c_cflag & CLOCAL, 0u);
  EXPECT_EQ(t.c_lflag & (ECHO | ICANON | ISIG), 0u);
  EXPECT_EQ(t.c_iflag & (IXON | IXOFF | ICRNL | INLCR), 0u);
  EXPECT_EQ(t.c_oflag & OPOST, 0u);
  // Bytes cross unchanged both ways (CR, LF, XON/XOFF included).
  const auto deadline = [] { return Clock::now() + 100ms; };
  ASSERT_TRUE(client.send("POS? 1\r\x11\x13\n", deadline()));
  EXPECT_EQ(pty.read_master(10), "POS? 1\r\x11\x13\n");
  const std::string reply = "1=0.5 \r\n2=1\nrest";
  ASSERT_EQ(::write(pty.master, reply.data(), reply.size()), static_cast<ssize_t>(reply.size()));
  std::string got;
  ASSERT_TRUE(client.read_until(got, line_end, deadline())) << client.error();
  EXPECT_EQ(got, "1=0.5 \r\n");
  // A silent line: the read gives up at its deadline.
  got.clear();
  client.discard_input();
  const auto t0 = Clock::now();
  EXPECT_FALSE(client.read_until(got, line_end, Clock::now() + 50ms));
  const double waited = std::chrono::duration<double>(Clock::now() - t0).count();
  EXPECT_GE(waited, 0.045);
  EXPECT_LT(waited, 0.5);
  EXPECT_EQ(client.error(), "no reply within the timeout");
  // Unplugged: the next read fails at once instead of waiting for its deadline.
  pty.unplug();
  const auto t1 = Clock::now();
  EXPECT_FALSE(client.read_until(got, line_end, Clock::now() + 2s));
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t1).count(), 0.5) << client.error();
  EXPECT_EQ(client.error(), "the serial line hung up");
  EXPECT_FALSE(client.send("x\n", Clock::now() + 50ms));
}

TEST(SerialLine, TheBaudAndHardwareFlowControlAreWhatTheConnectionSays) {
  Pty pty;
  LineClient client;
  client.open(parse_connection(pty.slave + ",flow=rtscts", "anc300", kAnc300DefaultBaud), 1.0);
  termios t = pty.settings();
  EXPECT_EQ(::cfgetospeed(&t), B38400);
  EXPECT_NE(t.c_cflag & CRTSCTS, 0u);
  client.close();
  client.open(parse_connection(pty.slave + ",baud=9600", "anc300", kAnc300DefaultBaud), 1.0);
  t = pty.settings();
  EXPECT_EQ(::cfgetospeed(&t), B9600);
  EXPECT_EQ(t.c_cflag & CRTSCTS, 0u);
}

// The platform's refusal: one line naming the path, exit 3.
std::string expect_refused(const std::string& connection) {
  try {
    platform::make_platform(serial_gcs2_config(connection));
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.exit_code(), ExitCode::kInvalidInput) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    return what;
  }
  ADD_FAILURE() << connection << " was not refused";
  return {};
}

TEST(SerialLine, APathThatIsNotThereOrNotATtyIsRefusedInOneLine) {
  const std::string missing = expect_refused("/dev/ttyUSB-not-there-30");
  EXPECT_NE(missing.find("/dev/ttyUSB-not-there-30"), std::string::npos) << missing;
  EXPECT_NE(missing.find("No such file or directory"), std::string::npos) << missing;
  const test::TempDir dir;
  const std::string file = (dir.path() / "not_a_tty").string();
  std::ofstream(file) << "1=0\n";
  const std::string regular = expect_refused(file);
  EXPECT_NE(regular.find(file + ": a regular file, not a serial port (tty)"), std::string::npos) << regular;
  const std::string null = expect_refused("/dev/null");
  EXPECT_NE(null.find("/dev/null: not a serial port (tty)"), std::string::npos) << null;
}

TEST(SerialLine, ThePiGcs2DriverConfiguresAndMovesTheAxesOverTheLine) {
  FakeGcs2 fake(test::FakeController::Transport::kPty);
  // The controller here is a thread of this process, which a loaded machine may starve for longer
  // than the default 0.1 s reply timeout (the timeout's own rule is tested below): 1 s.
  auto p = platform::make_platform(serial_gcs2_config(fake.server.tty_path() + ",timeout_s=1"));
  EXPECT_FALSE(p->simulated());
  EXPECT_GE(fake.server.count("*IDN?"), 1);
  EXPECT_GE(fake.server.count("SAI?"), 1);
  const Eigen::Vector3d goal(20e-6, -15e-6, 10e-6);
  Console console(*p, goal);
  run_paced(*p, 0.3);
  std::size_t allocations = 0;
  const int polls_before = fake.server.count("POS?");
  double elapsed = 0.0;
  {
    test::AllocationGuard guard(std::this_thread::get_id());
    elapsed = run_paced(*p, 1.0);
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_FALSE(p->faulted());
  // The bus thread starved for a stale window (a loaded machine) leaves a reading stale, as it
  // must say; a reading comes again once it runs.
  const auto fresh = [&] {
    return p->axis(0).measurement_fresh() && p->axis(1).measurement_fresh() && p->axis(2).measurement_fresh();
  };
  if (!fresh()) run_paced(*p, 2.0, fresh);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(fake.x_mm(i) * 1e-3, goal[i], 1e-9) << "axis " << i;
    EXPECT_NEAR(p->axis(i).position_m(), goal[i], 1e-9) << "axis " << i;
    EXPECT_TRUE(p->axis(i).measurement_fresh()) << "axis " << i;
  }
  const double poll_Hz = (fake.server.count("POS?") - polls_before) / elapsed;
  // Asked every 2 ms; the contract is a reading within every stale window (50 ms), whatever the
  // machine's load (the rate itself is measured by bench/driver_bench).
  EXPECT_GT(poll_Hz, 20.0);
  std::cout << "[ gcs2 over a pty ] POS? polled at " << poll_Hz << " Hz, " << fake.server.count("MOV")
            << " MOV\n";
}

TEST(SerialLine, UnpluggingTheLineMidMovePutsThePlatformInItsSafeStateWithinOneTimeout) {
  FakeGcs2 fake(test::FakeController::Transport::kPty);
  constexpr double kTimeout = 0.1;  // the default reply timeout
  // Under a sanitizer the bus thread is starved beside the instrumented loop for longer than the
  // default stale window (50 ms) now and then, faulting the platform before the unplugging: this
  // test is about the line's loss, not the window.
  auto p = platform::make_platform(
      serial_gcs2_config(fake.server.tty_path() + (MC_UNDER_SANITIZER ? ",stale_s=0.5" : "")));
  Console console(*p, {30e-6, 0, 0});
  // At least 0.3 s, until engaged: the driver's bus thread, starved beside other paced tests
  // under ASan, can leave the axes' readings stale for a while (seen in a CI-like run).
  run_paced(*p, 3.0, [&] { return p->loop().time_s() >= 0.3 && p->teleop().engaged; });
  ASSERT_FALSE(p->faulted());
  ASSERT_TRUE(p->teleop().engaged);
  fake.mode = Mode::kDisconnect;  // the next POS? closes the master
  const double t = run_paced(*p, 2.0, [&] { return p->faulted(); });
  ASSERT_TRUE(p->faulted()) << "no fault after 2 s";
  EXPECT_TRUE(fake.server.unplugged());
  std::cout << "[ gcs2 over a pty, unplugged ] platform in its safe state after " << 1e3 * t << " ms\n";
  EXPECT_LE(t, kTimeout + 0.002 + test::kFaultSlack_s);  // one timeout, one poll, and the machine's slack
  for (int i = 0; i < 3; ++i) EXPECT_EQ(p->axis(i).state(), devices::Lifecycle::kFault);
  run_paced(*p, 0.05);
  EXPECT_FALSE(p->teleop().engaged);
  EXPECT_FALSE(p->axis(0).measurement_fresh());
  const auto t0 = Clock::now();
  p.reset();  // shut down: nothing hangs
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 1.0);
}

// An ANC300 serial console (no password prompt: that is the telnet console's) counting the periods
// axis 1 is sent.
struct SerialAnc300 {
  std::mutex m;
  long long periods = 0;
  test::FakeController server{
      [this](const std::string& line) { return answer(line); }, {}, test::FakeController::Transport::kPty};
  test::FakeController::Answer answer(const std::string& line) {
    std::lock_guard lock(m);
    std::istringstream in(line);
    std::string c;
    int axis = 0;
    long long n = 1;
    in >> c >> axis >> n;
    if (c == "ver") return {"attocube ANC300 fake\r\nOK\r\n"};
    if (c == "getser") return {"serial number = ANM-FAKE\r\nOK\r\n"};
    if (axis == 1 && (c == "stepu" || c == "stepd")) periods += c == "stepu" ? n : -n;
    return {"OK\r\n"};
  }
  long long count() {
    std::lock_guard lock(m);
    return periods;
  }
};

TEST(SerialLine, TheAnc300DriverSendsNoPasswordAndStepsOverTheLine) {
  SerialAnc300 fake;
  register_vendor_drivers();
  PlatformConfig c;
  c.devices.driver = "anc300";
  c.devices.connection = fake.server.tty_path() + ",step_up_nm=20,step_down_nm=25";
  auto p = platform::make_platform(c);
  Console console(*p, {1e-6, 0, 0});
  run_paced(*p, 1.0);
  ASSERT_FALSE(p->faulted());
  EXPECT_EQ(fake.count(), 50);  // 1 um at 20 nm a period
  const auto lines = fake.server.lines();
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines.front(), "echo off");  // no password line before it
  p->fault_all();
  EXPECT_TRUE(test::eventually([&] { return fake.server.count("setm 1 gnd") > 0; }, 1000ms));
}

}  // namespace serial_line_test
}  // namespace mc::drivers
