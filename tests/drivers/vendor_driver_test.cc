// The drivers against a scriptable controller in this process (loopback, port 0): the
// pi-gcs2 driver runs the whole platform (console goal -> coupling -> MOV; POS? -> measurements)
// without allocating in the loop, checks the controller's axes at configure, and every bus fault
// (a reply later than the timeout, a truncated line, garbage, a disconnect mid-move, a controller
// error) puts the platform in its safe state within one timeout, the controller halted (HLT) where
// the connection still stands; the platform's e-stop sends HLT; recover() reconnects. The anc300
// driver logs in, steps to the target (counted), and grounds its axes on the safe state.

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include "drivers/fake_controller.h"
#include "drivers/gcs2_test_rig.h"
#include "microcobot/core/error.h"
#include "microcobot/drivers/anc300_codec.h"
#include "microcobot/drivers/anc300_driver.h"
#include "microcobot/drivers/gcs2_codec.h"
#include "microcobot/drivers/gcs2_driver.h"
#include "microcobot/drivers/register_drivers.h"
#include "microcobot/platform/driver_registry.h"
#include "support/counting_allocator.h"
#include "support/sanitizers.h"
#include "support/test_support.h"

namespace mc::drivers {
namespace vendor_driver_test {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using platform::Platform;
using platform::PlatformConfig;

using namespace gcs2_test_rig;

TEST(VendorDriverCodec, TheClientSideParsesRepliesAndRefusesWhatIsNotOne) {
  // GCS: a reply ends at the first LF not preceded by a space; what follows stays for the next.
  EXPECT_EQ(gcs2::reply_end("1=0.5 \n2=1\n3=2\n"), 11u);
  EXPECT_EQ(gcs2::reply_end("1=0.5 \n2=1"), 0u);
  EXPECT_EQ(gcs2::reply_lines("0 1 1=0.5 \n0 1 2=1\n"), (std::vector<std::string>{"1=0.5", "2=1"}));
  EXPECT_EQ(gcs2::parse_error_reply("7\n"), 7);
  EXPECT_EQ(gcs2::parse_error_reply("0 1 10\n"), 10);
  EXPECT_FALSE(gcs2::parse_error_reply("7.5\n"));
  EXPECT_FALSE(gcs2::parse_error_reply("1=0\n"));
  EXPECT_FALSE(gcs2::parse_error_reply("1 \n2\n"));
  // ANC300: a reply ends with its OK or ERROR line (a prompt before it tolerated).
  bool ok = false;
  const std::string r = "frequency = 500 Hz\r\nOK\r\nnext";
  EXPECT_EQ(anc300::reply_end(r, &ok), r.size() - 4);
  EXPECT_TRUE(ok);
  const std::string e = "> Axis in wrong mode\r\nERROR\r\n";
  EXPECT_EQ(anc300::reply_end(e, &ok), e.size());
  EXPECT_FALSE(ok);
  EXPECT_EQ(anc300::reply_end("OKAY\r\nOK"), 0u);
  EXPECT_EQ(anc300::reply_lines("> echo off\r\nOK\r\n"), (std::vector<std::string>{"echo off"}));
}

TEST(VendorDriverCodec, TheConnectionIsHostPortAndOptionsEachCheckedInOneLine) {
  const Connection c = parse_connection("127.0.0.1:50000,timeout_s=0.2,axes=A+B+C", "pi-gcs2");
  EXPECT_EQ(c.host, "127.0.0.1");
  EXPECT_EQ(c.port, 50000);
  EXPECT_EQ(c.options.at("axes"), "A+B+C");
  EXPECT_DOUBLE_EQ(gcs2_driver_params(c).timing.reply_timeout_s, 0.2);
  EXPECT_EQ(gcs2_driver_params(c).axes[2], "C");
  EXPECT_EQ(parse_connection("[::1]:7230", "anc300").host, "::1");
  for (const char* bad : {"COM3", "localhost", "127.0.0.1:", "127.0.0.1:0", "127.0.0.1:70000", "127.0.0.1:5x",
                          "127.0.0.1:50000,timeout_s", "127.0.0.1:1,a=1,a=2"})
    EXPECT_THROW(parse_connection(bad, "pi-gcs2"), InvalidParams) << bad;
  EXPECT_THROW(gcs2_driver_params(parse_connection("h:1,timeout_s=-1", "pi-gcs2")), InvalidParams);
  EXPECT_THROW(gcs2_driver_params(parse_connection("h:1,timeout_s=abc", "pi-gcs2")), InvalidParams);
  EXPECT_THROW(gcs2_driver_params(parse_connection("h:1,axes=1+1+2", "pi-gcs2")), InvalidParams);
  EXPECT_EQ(gcs2_driver_params(parse_connection("h:1,theta=U", "pi-gcs2")).theta, "U");
  EXPECT_THROW(gcs2_driver_params(parse_connection("h:1,theta=3", "pi-gcs2")), InvalidParams);
  EXPECT_THROW(gcs2_driver_params(parse_connection("h:1,theta=a b", "pi-gcs2")), InvalidParams);
  EXPECT_THROW(gcs2_driver_params(parse_connection("h:1,stale_s=0.001", "pi-gcs2")),
               InvalidParams);  // < poll
  EXPECT_THROW(anc300_driver_params(parse_connection("h:1,position=sensor", "anc300")), InvalidParams);
  EXPECT_THROW(anc300_driver_params(parse_connection("h:1,axes=1+2", "anc300")), InvalidParams);
  EXPECT_EQ(anc300_driver_params(parse_connection("h:1,theta=4", "anc300")).theta, 4);
  for (const char* bad : {"h:1,theta=8", "h:1,theta=4.5", "h:1,theta=x"})
    EXPECT_THROW(anc300_driver_params(parse_connection(bad, "anc300")), InvalidParams) << bad;
  EXPECT_TRUE(anc300_driver_params(parse_connection("h:1,position=getpos", "anc300")).sensor);
  try {
    gcs2_driver_params(parse_connection("h:1,speed=3", "pi-gcs2"));
    FAIL();
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("unknown option 'speed' (known: timeout_s"), std::string::npos)
        << e.what();
  }
}

TEST(Gcs2Driver, RunsThePlatformMovesEachAxisAndPollsWithoutAllocatingInTheLoop) {
  FakeGcs2 fake;
  auto p = platform::make_platform(gcs2_config(fake.server.port()));
  EXPECT_FALSE(p->simulated());
  EXPECT_TRUE(p->axis(0).position_controlled());
  const Eigen::Vector3d goal(20e-6, -15e-6, 10e-6);
  Console console(*p, goal);
  run_paced(*p, 0.3);  // the coupling engages on fresh measurements
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
  for (int i = 0; i < 3; ++i) {
    // The controller was sent the goal (1 nm on the wire) and the platform measures it back.
    EXPECT_NEAR(fake.x_mm(i) * 1e-3, goal[i], 1e-9) << "axis " << i;
    EXPECT_NEAR(p->axis(i).position_m(), goal[i], 1e-9) << "axis " << i;
    EXPECT_TRUE(p->axis(i).measurement_fresh());
  }
  // POS? every 2 ms (the poll period): at least a third of that rate on a loaded machine.
  const double poll_Hz = (fake.server.count("POS?") - polls_before) / elapsed;
  // Asked every 2 ms; the contract is a reading within every stale window (50 ms), whatever the
  // machine's load (the rate itself is measured by bench/driver_bench).
  EXPECT_GT(poll_Hz, 20.0);
  std::cout << "[ gcs2 ] POS? polled at " << poll_Hz << " Hz, " << fake.server.count("MOV") << " MOV\n";
  // Each MOV was followed by ERR? (the error register drained after every set command).
  const auto lines = fake.server.lines();
  for (std::size_t k = 0; k + 1 < lines.size(); ++k)
    if (lines[k].rfind("MOV", 0) == 0) {
      EXPECT_EQ(lines[k + 1], "ERR?") << "after " << lines[k];
    }
}

TEST(Gcs2Driver, AControllerWithoutTheConfiguredAxesIsRefusedNamingWhatItHas) {
  FakeGcs2 fake;
  fake.axes_reply = "A \nB\n";
  try {
    platform::make_platform(gcs2_config(fake.server.port()));
    FAIL() << "configured on a controller without axes 1 2 3";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("SAI? ALL lists axes [A, B]: no axis '1'"), std::string::npos)
        << e.what();
  }
  // The rotary axis (option theta) must be one of the controller's too.
  fake.axes_reply = "1 \n2 \n3\n";
  try {
    platform::make_platform(gcs2_config(fake.server.port(), ",theta=4"));
    FAIL() << "configured a rotary axis on a controller without axis 4";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("SAI? ALL lists axes [1, 2, 3]: no axis '4'"), std::string::npos)
        << e.what();
  }
  // Options are checked before anything is opened.
  EXPECT_THROW(platform::make_platform(gcs2_config(fake.server.port(), ",axes=1+2")), InvalidParams);
  EXPECT_THROW(platform::make_platform(gcs2_config(fake.server.port(), ",theta=2")), InvalidParams);
  PlatformConfig no_rotary = gcs2_config(fake.server.port(), ",theta=4");
  no_rotary.stage.rotary.enabled = false;
  EXPECT_THROW(platform::make_platform(no_rotary), InvalidParams);
  EXPECT_THROW(platform::make_platform(gcs2_config(fake.server.port(), ",poll=1")), InvalidParams);
}

TEST(Gcs2Driver, AWindowsPortNameIsRefusedInOneLine) {
  register_vendor_drivers();
  PlatformConfig c;
  c.devices.driver = "pi-gcs2";
  c.devices.connection = "COM3";
  try {
    platform::make_platform(c);
    FAIL();
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("'COM3': a Windows port name"), std::string::npos) << e.what();
  }
}

// One fault: the platform moving, then the controller misbehaves (`mode`). The driver must fault
// the platform within one reply timeout (plus one poll period and the loop's own millisecond),
// with the controller halted where the connection still stands; nothing hangs.
void expect_safe_within_one_timeout(Mode mode, bool halt_expected) {
  FakeGcs2 fake;
  constexpr double kTimeout = 0.1;  // the default reply timeout
  auto p = platform::make_platform(gcs2_config(fake.server.port()));
  Console console(*p, {30e-6, 0, 0});
  run_paced(*p, 0.3);
  ASSERT_FALSE(p->faulted());
  ASSERT_TRUE(p->teleop().engaged);
  const int halts_before = fake.halts.load();
  fake.mode = mode;
  const double t = run_paced(*p, 2.0, [&] { return p->faulted(); });
  ASSERT_TRUE(p->faulted()) << "no fault after 2 s";
  std::cout << "[ gcs2 fault " << static_cast<int>(mode) << " ] platform in its safe state after " << 1e3 * t
            << " ms\n";
  EXPECT_LE(t, kTimeout + 0.002 + test::kFaultSlack_s);  // one timeout, one poll, and the machine's slack
  for (int i = 0; i < 3; ++i) EXPECT_EQ(p->axis(i).state(), devices::Lifecycle::kFault);
  EXPECT_EQ(p->gripper().state(), devices::Lifecycle::kFault);
  run_paced(*p, 0.05);
  EXPECT_FALSE(p->teleop().engaged);
  EXPECT_FALSE(p->axis(0).measurement_fresh());
  if (halt_expected) {
    EXPECT_TRUE(test::eventually([&] { return fake.halts.load() > halts_before; }, 1000ms))
        << "no HLT sent to the controller";
  }
  const auto t0 = Clock::now();
  p.reset();  // shut down: nothing hangs
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 1.0);
}

TEST(Gcs2Driver, AReplySlowerThanTheTimeoutPutsThePlatformInItsSafeState) {
  expect_safe_within_one_timeout(Mode::kSlow, true);
}
TEST(Gcs2Driver, ATruncatedReplyPutsThePlatformInItsSafeState) {
  expect_safe_within_one_timeout(Mode::kTruncated, true);
}
TEST(Gcs2Driver, AGarbledReplyPutsThePlatformInItsSafeState) {
  expect_safe_within_one_timeout(Mode::kGarbage, true);
}
TEST(Gcs2Driver, ADisconnectMidMovePutsThePlatformInItsSafeState) {
  expect_safe_within_one_timeout(Mode::kDisconnect, false);
}
TEST(Gcs2Driver, AControllerErrorAfterAMovePutsThePlatformInItsSafeState) {
  FakeGcs2 fake;
  auto p = platform::make_platform(gcs2_config(fake.server.port()));
  Console console(*p, {0, 0, 0});
  run_paced(*p, 0.3);
  fake.mode = Mode::kError;
  console.in.goal_m = console.home + Eigen::Vector3d(0, 40e-6, 0);  // MOVs, each answered by ERR? 7
  const double t = run_paced(*p, 2.0, [&] { return p->faulted(); });
  ASSERT_TRUE(p->faulted());
  EXPECT_LE(t, 0.1 + 0.002 + 0.05);
  EXPECT_TRUE(test::eventually([&] { return fake.halts.load() > 0; }, 1000ms));
  std::cout << "[ gcs2 controller error ] safe state after " << 1e3 * t << " ms\n";
}

TEST(Gcs2Driver, ThePlatformsEstopHaltsTheControllerAndRecoverReconnects) {
  FakeGcs2 fake;
  auto p = platform::make_platform(gcs2_config(fake.server.port()));
  Console console(*p, {5e-6, 0, 0});
  run_paced(*p, 0.3);
  ASSERT_NEAR(fake.x_mm(0), 5e-3, 1e-6);
  p->fault_all();  // the operator's e-stop
  const auto t0 = Clock::now();
  ASSERT_TRUE(test::eventually([&] { return fake.halts.load() > 0; }, 1000ms));
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 0.1);
  // A disconnect, then the reset: the driver connects again and runs.
  fake.mode = Mode::kDisconnect;
  run_paced(*p, 0.3);
  fake.mode = Mode::kNormal;
  p->recover();
  EXPECT_EQ(fake.server.connections(), 2);
  console.in.goal_m = console.home + Eigen::Vector3d(-5e-6, 0, 0);
  run_paced(*p, 0.5);
  EXPECT_FALSE(p->faulted());
  EXPECT_NEAR(fake.x_mm(0), -5e-3, 1e-6);
}

// An ANC300 console whose axes count the periods they are sent (20 nm each).
struct FakeAnc300 {
  std::mutex m;
  long long periods[3] = {0, 0, 0};
  std::atomic<bool> refuse_steps{false};
  test::FakeController server{[this](const std::string& line) { return answer(line); },
                              "attocube ANC300\r\nAuthorization code: "};
  bool authorized = false;

  test::FakeController::Answer answer(const std::string& line) {
    std::lock_guard lock(m);
    if (!authorized) {
      authorized = line == "123456";
      return {authorized ? "\r\nAuthorization success\r\n> " : "\r\nAuthorization failed\r\n", !authorized};
    }
    std::istringstream in(line);
    std::string c;
    int axis = 0;
    long long n = 1;
    in >> c >> axis >> n;
    if (c == "echo") return {"echo off\r\nOK\r\n"};
    if (c == "ver") return {"attocube ANC300 fake\r\nOK\r\n"};
    if (axis < 1 || axis > 3) return {"Invalid axis\r\nERROR\r\n"};
    if (c == "getser") return {"serial number = ANM-FAKE\r\nOK\r\n"};
    if (c == "stepu" || c == "stepd") {
      if (refuse_steps) return {"Axis in wrong mode\r\nERROR\r\n"};
      periods[axis - 1] += c == "stepu" ? n : -n;
    }
    return {"OK\r\n"};
  }
  long long count(int i) {
    std::lock_guard lock(m);
    return periods[i];
  }
};

PlatformConfig anc300_config(std::uint16_t port, const std::string& options) {
  register_vendor_drivers();
  PlatformConfig c;
  c.devices.driver = "anc300";
  c.devices.connection = fmt::format("127.0.0.1:{}{}", port, options);
  return c;
}

TEST(Anc300Driver, StepsEachAxisToItsTargetByCountingAndGroundsItOnTheSafeState) {
  FakeAnc300 fake;
  auto p = platform::make_platform(anc300_config(fake.server.port(), ",step_up_nm=20,step_down_nm=25"));
  EXPECT_TRUE(p->axis(0).position_controlled());
  Console console(*p, {1e-6, -1e-6, 0.4e-6});
  std::size_t allocations = 0;
  {
    test::AllocationGuard guard(std::this_thread::get_id());
    run_paced(*p, 1.0);
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  ASSERT_FALSE(p->faulted());
  // 1 um up at 20 nm a period, 1 um down at 25 nm, 0.4 um up: 50, -40, 20 periods.
  EXPECT_EQ(fake.count(0), 50);
  EXPECT_EQ(fake.count(1), -40);
  EXPECT_EQ(fake.count(2), 20);
  EXPECT_NEAR(p->axis(0).position_m(), 1e-6, 1e-12);
  const auto lines = fake.server.lines();
  EXPECT_EQ(lines.at(1), "echo off");
  EXPECT_NE(std::find(lines.begin(), lines.end(), "setm 1 stp"), lines.end());
  EXPECT_NE(std::find(lines.begin(), lines.end(), "setf 1 1000"), lines.end());
  EXPECT_NE(std::find(lines.begin(), lines.end(), "setv 1 60.000"), lines.end());
  p->fault_all();
  ASSERT_TRUE(test::eventually([&] { return fake.server.count("setm 3 gnd") > 0; }, 1000ms));
  EXPECT_GE(fake.server.count("stop 1"), 1);
}

TEST(Anc300Driver, AnErrorLineFaultsThePlatformAndAWrongPasswordIsRefused) {
  FakeAnc300 fake;
  auto p = platform::make_platform(anc300_config(fake.server.port(), ",step_up_nm=20,step_down_nm=20"));
  Console console(*p, {0, 0, 0});
  run_paced(*p, 0.2);
  fake.refuse_steps = true;
  console.in.goal_m = console.home + Eigen::Vector3d(2e-6, 0, 0);
  const double t = run_paced(*p, 2.0, [&] { return p->faulted(); });
  ASSERT_TRUE(p->faulted());
  EXPECT_LE(t, 0.2 + 0.005 + 0.05);  // the stepping command's error at once, well within a timeout
  EXPECT_TRUE(test::eventually([&] { return fake.server.count("setm 1 gnd") > 0; }, 1000ms));
  p.reset();
  FakeAnc300 other;
  try {
    platform::make_platform(
        anc300_config(other.server.port(), ",password=wrong,step_up_nm=20,step_down_nm=20"));
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("refused the password"), std::string::npos) << e.what();
  }
}

}  // namespace vendor_driver_test
}  // namespace mc::drivers
