// The smaract-mcs2 driver against a scriptable MCS2 in this process (loopback, port 0): it checks
// the controller at configure (identity, channel count, sensors, reference), runs the whole
// platform (console goal -> coupling -> :MOVE<n>; :CHAN<n>:POS? -> measurements) without
// allocating in the loop, and every bus fault (a controller error in the queue, a reply later
// than the timeout, garbage, a disconnect mid-move) puts the platform in its safe state within one
// timeout, :STOP<n> sent on every channel where the connection still stands; the platform's e-stop
// sends :STOP; recover() reconnects.

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <deque>
#include <iostream>
#include <mutex>
#include <thread>

#include <fmt/format.h>

#include "drivers/fake_controller.h"
#include "drivers/gcs2_test_rig.h"
#include "microcobot/core/error.h"
#include "microcobot/drivers/mcs2_codec.h"
#include "microcobot/drivers/mcs2_driver.h"
#include "microcobot/drivers/register_drivers.h"
#include "microcobot/platform/driver_registry.h"
#include "support/counting_allocator.h"
#include "support/sanitizers.h"
#include "support/test_support.h"

namespace mc::drivers {
namespace mcs2_driver_test {

using namespace std::chrono_literals;
using gcs2_test_rig::Console;
using gcs2_test_rig::run_paced;
using platform::PlatformConfig;

enum class Mode { kNormal, kSlow, kGarbage, kDisconnect, kError };

// An MCS2 of four channels whose closed-loop moves reach their target at once; unreferenced at
// power-up. Each line is one command (the driver sends no more per line).
struct FakeMcs2 {
  std::atomic<Mode> mode{Mode::kNormal};
  std::string idn = "SmarAct GmbH,MCS2,MCS2-00001234,1.4.2";
  int channels = 4;
  int no_sensor = -1;
  bool refuse_reference = false;  // :REF answered by error 262 (the amplifier off)
  bool referenced[4] = {false, false, false, false};
  std::mutex m;
  std::int64_t pos_pm[4] = {0, 0, 0, 0};
  int move_mode[4] = {0, 0, 0, 0};
  std::int64_t steps[4] = {0, 0, 0, 0};    // step mode: the periods played, signed
  std::deque<int> errors{mcs2::kAborted};  // stale: drained at configure
  std::atomic<int> stops[4] = {0, 0, 0, 0};
  test::FakeController server{[this](const std::string& line) { return answer(line); }};

  test::FakeController::Answer answer(const std::string& line) {
    std::lock_guard lock(m);
    mcs2::Command c;
    if (mcs2::parse_command(line, c) != mcs2::kNoError) return {};
    const auto n = static_cast<std::size_t>(std::clamp(c.index, 0, 3));
    auto reply = [](auto v) { return test::FakeController::Answer{fmt::format("{}\r\n", v)}; };
    const std::string& h = c.header;
    if (h == "*IDN") return reply(idn);
    if (h == "SYST:ERR:COUN") return reply(errors.size());
    if (h == "SYST:ERR:NEXT") {
      const int e = errors.empty() ? 0 : errors.front();
      if (!errors.empty()) errors.pop_front();
      return reply(mcs2::format_error(e));
    }
    if (h == "DEV:NOCH") return reply(channels);
    if (h == "CHAN:STAT") {
      std::uint32_t s = mcs2::channel_state::kAmplifierEnabled;
      if (c.index != no_sensor) s |= mcs2::channel_state::kSensorPresent;
      if (referenced[n]) s |= mcs2::channel_state::kIsReferenced | mcs2::channel_state::kClosedLoopActive;
      return reply(s);
    }
    if (h == "CHAN:TUN:BASE:UNIT") return reply(n == 3 ? mcs2::kUnitDegree : mcs2::kUnitMeter);
    if (h == "CHAN:RLIM:MIN") return reply(-5'000'000'000LL);  // 5 mm, 5 deg
    if (h == "CHAN:RLIM:MAX") return reply(5'000'000'000LL);
    if (h == "CHAN:VEL" && c.query) return reply(1'000'000'000LL);  // 1 mm/s
    if (h == "REF" && refuse_reference) {
      errors.push_back(mcs2::kAmplifierDisabled);
    } else if (h == "REF") {
      referenced[n] = true;
      pos_pm[n] = 0;
    }
    if (h == "STOP") ++stops[n];
    if (h == "CHAN:MMOD" && !c.query) move_mode[n] = static_cast<int>(*mcs2::parse_integer(c.args.at(0)));
    if (h == "MOVE" && move_mode[n] == mcs2::kStep) {
      // Step mode needs no sensor or reference: the periods are played at once.
      if (mode == Mode::kError) {
        errors.push_back(mcs2::kAmplifierDisabled);
      } else {
        steps[n] += *mcs2::parse_integer(c.args.at(0));
      }
    } else if (h == "MOVE") {
      if (!referenced[n]) {
        errors.push_back(mcs2::kNotReferenced);
      } else if (mode == Mode::kError) {
        errors.push_back(mcs2::kAmplifierDisabled);
      } else {
        pos_pm[n] = *mcs2::parse_rounded(c.args.at(0));
      }
    }
    if (h == "CHAN:POS" && c.query && static_cast<int>(n) == no_sensor) {
      errors.push_back(mcs2::kNoSensorPresent);
      return reply(0);
    }
    if (h == "CHAN:POS" && c.query) {
      switch (mode.load()) {
        case Mode::kSlow:
          return {};  // never answered
        case Mode::kGarbage:
          return {"\x01\x7f@@ garbage\r\n"};
        case Mode::kDisconnect:
          return {"", true};
        default:
          return reply(pos_pm[n]);
      }
    }
    return {};  // MMOD, HOLD, VEL: set commands have no reply
  }
  double x_m(int i) {
    std::lock_guard lock(m);
    return static_cast<double>(pos_pm[i]) * 1e-12;
  }
};

PlatformConfig mcs2_config(std::uint16_t port, const std::string& options = "") {
  register_vendor_drivers();
  PlatformConfig c;
  c.devices.driver = "smaract-mcs2";
  c.devices.connection = fmt::format("127.0.0.1:{}{}", port, options);
  return c;
}

TEST(Mcs2Driver, TheConnectionOptionsAreCheckedInOneLine) {
  const auto p = mcs2_driver_params(parse_connection("h:1,channels=3+4+5,theta=0,reference=require", "x"));
  EXPECT_EQ(p.channels[2], 5);
  EXPECT_EQ(p.theta, 0);
  EXPECT_FALSE(p.reference);
  for (const char* bad :
       {"h:1,channels=0+1", "h:1,channels=0+0+1", "h:1,channels=a+1+2", "h:1,theta=24", "h:1,theta=-1",
        "h:1,theta=1", "h:1,reference=yes", "h:1,velocity_mm_s=-1", "h:1,speed=1"})
    EXPECT_THROW(mcs2_driver_params(parse_connection(bad, "smaract-mcs2")), InvalidParams) << bad;
  // The sensorless channels' options: a bad value, or one without sensorless=step, refused in one
  // line naming the option.
  const auto s = mcs2_driver_params(parse_connection(
      "h:1,sensorless=step,voltage_V=40,frequency_Hz=2000,step_up_nm=20,step_down_nm=25", "x"));
  EXPECT_TRUE(s.sensorless_step);
  EXPECT_EQ(s.step.voltage_V, 40.0);
  EXPECT_EQ(s.step.frequency_Hz, 2000.0);
  EXPECT_NEAR(s.step.step_down_m, 25e-9, 1e-18);
  EXPECT_FALSE(mcs2_driver_params(parse_connection("h:1", "x")).sensorless_step);
  for (const auto& [bad, option] : std::vector<std::pair<const char*, const char*>>{
           {"h:1,sensorless=yes", "option sensorless"},
           {"h:1,sensorless=", "option sensorless"},
           {"h:1,voltage_V=40", "option voltage_V"},
           {"h:1,sensorless=step,voltage_V=101", "option voltage_V"},
           {"h:1,sensorless=step,voltage_V=0", "option voltage_V"},
           {"h:1,sensorless=step,frequency_Hz=20001", "option frequency_Hz"},
           {"h:1,sensorless=step,frequency_Hz=abc", "option frequency_Hz"},
           {"h:1,sensorless=step,max_run_s=2", "option max_run_s"},
           {"h:1,sensorless=step,frequency_Hz=10,max_run_s=0.01", "option max_run_s"},
           {"h:1,sensorless=step,step_up_nm=-1", "option step_up_nm"},
           {"h:1,sensorless=step,deadband_nm=1e6", "option deadband_nm"}}) {
    try {
      mcs2_driver_params(parse_connection(bad, "smaract-mcs2"));
      ADD_FAILURE() << bad << ": accepted";
    } catch (const InvalidParams& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(option), std::string::npos) << bad << ": " << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
  // A serial path is refused (the MCS2's ASCII interface is its network port); so is theta without
  // the platform's rotary axis.
  auto serial = mcs2_config(1);
  serial.devices.connection = "/dev/ttyUSB0";
  EXPECT_THROW(platform::make_platform(serial), InvalidParams);
  auto no_rotary = mcs2_config(1, ",theta=3");
  no_rotary.stage.rotary.enabled = false;
  EXPECT_THROW(platform::make_platform(no_rotary), InvalidParams);
}

TEST(Mcs2Driver, ReferencesRunsThePlatformToTheGoalOnEveryAxisWithoutAllocatingInTheLoop) {
  FakeMcs2 fake;
  auto p = platform::make_platform(mcs2_config(fake.server.port(), ",theta=3,velocity_mm_s=1"));
  EXPECT_FALSE(p->simulated());
  ASSERT_TRUE(p->has_rotary());
  for (int c = 0; c < 4; ++c) EXPECT_EQ(fake.server.count(fmt::format(":REF{}", c)), 1) << c;
  EXPECT_EQ(fake.server.count(":CHAN0:MMOD 0"), 1);
  EXPECT_EQ(fake.server.count(":CHAN3:HOLD -1"), 1);
  EXPECT_EQ(fake.server.count(":CHAN2:VEL 1000000000"), 1);  // 1 mm/s in pm/s, X, Y, Z only
  EXPECT_EQ(fake.server.count(":CHAN3:VEL "), 0);
  const Eigen::Vector3d goal(20e-6, -15e-6, 10e-6);
  Console console(*p, goal);
  console.in.has_theta_goal = true;
  console.in.theta_goal_rad = 0.01;
  console.in.theta_speed_rad_s = 0.16;
  run_paced(*p, 0.3);
  std::size_t allocations = 0;
  const int polls_before = fake.server.count(":CHAN0:POS?");
  double elapsed = 0.0;
  {
    test::AllocationGuard guard(std::this_thread::get_id());
    elapsed = run_paced(*p, 1.0);
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  ASSERT_FALSE(p->faulted());
  for (int i = 0; i < 3; ++i) {
    // The controller was sent the goal (1 pm on the wire) and the platform measures it back.
    EXPECT_NEAR(fake.x_m(i), goal[i], 1e-12) << "axis " << i;
    EXPECT_NEAR(p->axis(i).position_m(), goal[i], 1e-12) << "axis " << i;
  }
  // Theta: 0.01 rad is 572957795 ndeg (1 ndeg: 87 fm of arc at 5 mm).
  EXPECT_NEAR(static_cast<double>(fake.x_m(3)) * 1e12, 0.01 * 180 / M_PI * 1e9, 1.0);
  EXPECT_NEAR(p->yaw_rad(), 0.01, 1e-8);
  const double poll_Hz = (fake.server.count(":CHAN0:POS?") - polls_before) / elapsed;
  EXPECT_GT(poll_Hz, 20.0);  // asked every 2 ms; the contract is a reading within every 50 ms
  std::cout << "[ mcs2 ] :CHAN0:POS? polled at " << poll_Hz << " Hz, " << fake.server.count(":MOVE0")
            << " :MOVE0\n";
  // Each :MOVE is followed by the error count, before the positions.
  const auto lines = fake.server.lines();
  for (std::size_t k = 0; k + 1 < lines.size(); ++k)
    if (lines[k].rfind(":MOVE", 0) == 0) {
      EXPECT_TRUE(lines[k + 1].rfind(":MOVE", 0) == 0 || lines[k + 1] == ":SYST:ERR:COUN?") << lines[k + 1];
    }
}

std::string configure_error(FakeMcs2& fake, const std::string& options = "") {
  try {
    platform::make_platform(mcs2_config(fake.server.port(), options));
  } catch (const Error& e) {
    return e.what();
  }
  return "configured";
}

TEST(Mcs2Driver, ConfigureRefusesAWrongIdentityTooFewChannelsNoSensorOrNoReferenceInOneLine) {
  const auto expect_one_line = [](const std::string& what, const std::string& part, std::uint16_t port) {
    EXPECT_NE(what.find(part), std::string::npos) << what;
    EXPECT_NE(what.find(fmt::format("smaract-mcs2 controller at 127.0.0.1:{}", port)), std::string::npos)
        << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  };
  {
    FakeMcs2 fake;
    fake.idn = "(c)2026 Physik Instrumente (PI) E-873";
    expect_one_line(configure_error(fake),
                    "*IDN? reads '(c)2026 Physik Instrumente (PI) E-873': not a SmarAct MCS2",
                    fake.server.port());
  }
  {
    FakeMcs2 fake;
    fake.channels = 2;
    expect_one_line(configure_error(fake), ":DEV:NOCH? reads 2: no channel 2", fake.server.port());
    fake.channels = 3;
    expect_one_line(configure_error(fake, ",theta=3"), ":DEV:NOCH? reads 3: no channel 3",
                    fake.server.port());
  }
  {
    FakeMcs2 fake;
    fake.no_sensor = 1;
    expect_one_line(configure_error(fake), "channel 1: no sensor present", fake.server.port());
    // The refusal names the option that drives it.
    expect_one_line(configure_error(fake), "option sensorless=step", fake.server.port());
    expect_one_line(configure_error(fake, ",sensorless=refuse"), "option sensorless=step",
                    fake.server.port());
  }
  {
    FakeMcs2 fake;
    expect_one_line(configure_error(fake, ",reference=require"), "reference=require", fake.server.port());
    EXPECT_EQ(fake.server.count(":REF"), 0);
    fake.refuse_reference = true;
    expect_one_line(configure_error(fake), "':REF0': controller error 262 (Amplifier disabled)",
                    fake.server.port());
    fake.refuse_reference = false;
    // Linear channels for X, Y, Z: the rotary one there is refused.
    expect_one_line(configure_error(fake, ",channels=0+1+3"), "channel 3: base unit 3", fake.server.port());
  }
}

// One fault: the platform moving, then the controller misbehaves. The driver must fault the
// platform within one reply timeout (plus one poll period and slack), :STOP<n> sent on every
// channel where the connection still stands.
void expect_safe_within_one_timeout(Mode mode, bool stop_expected) {
  FakeMcs2 fake;
  constexpr double kTimeout = 0.1;  // the default reply timeout
  auto p = platform::make_platform(mcs2_config(fake.server.port()));
  Console console(*p, {30e-6, 0, 0});
  run_paced(*p, 0.3);
  ASSERT_FALSE(p->faulted());
  ASSERT_TRUE(p->teleop().engaged);
  fake.mode = mode;
  if (mode == Mode::kError) console.in.goal_m = console.home + Eigen::Vector3d(0, 40e-6, 0);
  const double t = run_paced(*p, 2.0, [&] { return p->faulted(); });
  ASSERT_TRUE(p->faulted()) << "no fault after 2 s";
  std::cout << "[ mcs2 fault " << static_cast<int>(mode) << " ] platform in its safe state after " << 1e3 * t
            << " ms\n";
  EXPECT_LE(t, kTimeout + 0.002 + test::kFaultSlack_s);  // one timeout, one poll, and the machine's slack
  for (int i = 0; i < 3; ++i) EXPECT_EQ(p->axis(i).state(), devices::Lifecycle::kFault);
  run_paced(*p, 0.05);
  EXPECT_FALSE(p->teleop().engaged);
  EXPECT_FALSE(p->axis(0).measurement_fresh());
  if (stop_expected) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_TRUE(test::eventually([&] { return fake.stops[c].load() > 0; }, 1000ms)) << ":STOP" << c;
    }
  }
  const auto t0 = std::chrono::steady_clock::now();
  p.reset();  // shut down: nothing hangs
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0);
}

TEST(Mcs2Driver, AControllerErrorInTheQueuePutsThePlatformInItsSafeState) {
  expect_safe_within_one_timeout(Mode::kError, true);
}
TEST(Mcs2Driver, AReplySlowerThanTheTimeoutPutsThePlatformInItsSafeState) {
  expect_safe_within_one_timeout(Mode::kSlow, true);
}
TEST(Mcs2Driver, AGarbledReplyPutsThePlatformInItsSafeState) {
  expect_safe_within_one_timeout(Mode::kGarbage, true);
}
TEST(Mcs2Driver, ADisconnectMidMovePutsThePlatformInItsSafeState) {
  expect_safe_within_one_timeout(Mode::kDisconnect, false);
}

TEST(Mcs2Driver, TheControllersErrorTextIsTheFaultsReason) {
  FakeMcs2 fake;
  auto params = mcs2_driver_params(parse_connection(fmt::format("127.0.0.1:{}", fake.server.port()), "x"));
  Mcs2Controller controller(parse_connection(fmt::format("127.0.0.1:{}", fake.server.port()), "x"), params);
  controller.configure();
  EXPECT_EQ(controller.identity(), fake.idn);
  fake.mode = Mode::kError;
  controller.arm(1, true);
  controller.set_target(1, 1e-6);
  ASSERT_TRUE(test::eventually([&] { return controller.faulted(); }, 1000ms));
  EXPECT_EQ(controller.fault_reason(), "':MOVE1 1000000': controller error 262 (Amplifier disabled)");
  // The fault is raised, then the channel stopped: waited for, not read at once.
  EXPECT_TRUE(test::eventually([&] { return fake.stops[1].load() >= 1; }, 1000ms));
}

TEST(Mcs2Driver, ThePlatformsEstopStopsEveryChannelAndRecoverReconnects) {
  FakeMcs2 fake;
  auto p = platform::make_platform(mcs2_config(fake.server.port()));
  Console console(*p, {5e-6, 0, 0});
  run_paced(*p, 0.3);
  ASSERT_NEAR(fake.x_m(0), 5e-6, 1e-12);
  p->fault_all();  // the operator's e-stop
  const auto t0 = std::chrono::steady_clock::now();
  for (int c = 0; c < 3; ++c)
    ASSERT_TRUE(test::eventually([&] { return fake.stops[c].load() > 0; }, 1000ms)) << ":STOP" << c;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
            0.05 + test::kFaultSlack_s);
  fake.mode = Mode::kDisconnect;
  run_paced(*p, 0.3);
  fake.mode = Mode::kNormal;
  p->recover();
  EXPECT_EQ(fake.server.connections(), 2);
  console.in.goal_m = console.home + Eigen::Vector3d(-5e-6, 0, 0);
  run_paced(*p, 0.5);
  EXPECT_FALSE(p->faulted());
  EXPECT_NEAR(fake.x_m(0), -5e-6, 1e-12);
}

// A channel without sensor, with sensorless=step: stepped open loop in step mode, its position
// counted (the periods sent times the step the options give), each run once the previous is over,
// :STOP on the e-stop and on a fault; the closed-loop channels as before.
TEST(Mcs2Driver, ASensorlessChannelIsSteppedOpenLoopItsPositionCounted) {
  FakeMcs2 fake;
  fake.no_sensor = 2;
  auto p = platform::make_platform(mcs2_config(
      fake.server.port(), ",sensorless=step,voltage_V=40,frequency_Hz=2000,step_up_nm=20,step_down_nm=25"));
  EXPECT_EQ(fake.server.count(":CHAN2:MMOD 4"), 1);
  EXPECT_EQ(fake.server.count(":CHAN2:STEP:FREQ 2000"), 1);
  EXPECT_EQ(fake.server.count(":CHAN2:STEP:AMPL 26214"), 1);  // 40 V of 100 V: 65535 * 0.4
  EXPECT_EQ(fake.server.count(":CHAN2:HOLD"), 0);
  EXPECT_EQ(fake.server.count(":REF2"), 0);  // no reference mark without the sensor
  EXPECT_EQ(fake.server.count(":CHAN2:POS?"), 0);
  EXPECT_EQ(fake.server.count(":CHAN0:MMOD 0"), 1);
  EXPECT_EQ(fake.server.count(":REF0"), 1);
  const Eigen::Vector3d goal(5e-6, 0, 3e-6);
  Console console(*p, goal);
  run_paced(*p, 0.5);
  ASSERT_FALSE(p->faulted());
  EXPECT_NEAR(fake.x_m(0), goal[0], 1e-12);
  // 3 um up at 20 nm a period: 150 periods, in runs of at most 2000 Hz x 20 ms = 40.
  EXPECT_EQ(fake.steps[2], 150);
  EXPECT_NEAR(p->axis(2).position_m(), 3e-6, 1e-12);
  const auto lines = fake.server.lines();
  int runs = 0;
  for (const auto& l : lines)
    if (l.rfind(":MOVE2 ", 0) == 0) {
      ++runs;
      const long long n = std::stoll(l.substr(7));
      EXPECT_TRUE(n >= 1 && n <= 40) << l;
    }
  EXPECT_GE(runs, 4);  // 40 + 40 + 40 + 30 at least (the coupling's target ramps to the goal)
  // Down 2 um at 25 nm: 80 periods back.
  console.in.goal_m = console.home + Eigen::Vector3d(5e-6, 0, 1e-6);
  run_paced(*p, 0.5);
  EXPECT_EQ(fake.steps[2], 70);
  EXPECT_NEAR(p->axis(2).position_m(), 1e-6, 1e-12);
  // The e-stop stops the stepped channel too.
  const int stops = fake.stops[2].load();
  p->fault_all();
  EXPECT_TRUE(test::eventually([&] { return fake.stops[2].load() > stops; }, 1000ms));
  // A controller error faults the bus: the stepped channel is stopped with the others.
  p->recover();
  console.in.goal_m = console.home + Eigen::Vector3d(5e-6, 0, 3e-6);
  fake.mode = Mode::kError;
  const int before = fake.stops[2].load();
  run_paced(*p, 2.0, [&] { return p->faulted(); });
  ASSERT_TRUE(p->faulted());
  EXPECT_TRUE(test::eventually([&] { return fake.stops[2].load() > before; }, 1000ms));
}

}  // namespace mcs2_driver_test
}  // namespace mc::drivers
