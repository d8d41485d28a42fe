// The `pi-hexapod` driver against the hexapod twin in another process. A `microcobot serve
// --emulate gcs2-hexapod=127.0.0.1:0` child (a configuration with `positioner: parallel`; its port
// read from its stdout line `emulate gcs2-hexapod 127.0.0.1:PORT`) is the C-887; this process runs a
// platform whose parallel positioner is `pi-hexapod` on it, the console holding the deadman. The
// twin's platform, read through its own GCS port by a client of its own (POS?), must end each pose
// move within the twin's on-target tolerance; the loop never allocates while the positioner moves;
// the twin killed mid-move puts the platform in its safe state within one reply timeout.

#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <iostream>
#include <numbers>
#include <regex>
#include <thread>

#include <fmt/format.h>

#include "microcobot/drivers/gcs2_codec.h"
#include "microcobot/drivers/pi_hexapod.h"
#include "microcobot/drivers/register_drivers.h"
#include "microcobot/motion/pose.h"
#include "microcobot/platform/driver_registry.h"
#include "support/counting_allocator.h"
#include "support/sanitizers.h"
#include "support/test_support.h"

namespace mc::twins {
namespace pi_hexapod_driver_test {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using platform::Platform;
using platform::PlatformConfig;
using Pose6 = std::array<double, 6>;  // X, Y, Z [mm], U, V, W [deg]

constexpr double kRadPerDeg = std::numbers::pi / 180.0;
// The reply timeout the tests give the driver: the twin is another process, sanitized too under the
// sanitizer presets and sharing two loaded cores with the other tests.
constexpr double kTimeout_s = 1.0;

// The hexapod twin in its own process (a platform with the parallel positioner), killed at the end.
struct HexapodTwinProcess {
  test::TempDir dir;
  test::BackgroundCli cli;
  std::uint16_t port = 0;
  bool alive = true;
  HexapodTwinProcess() {
    test::write_text(dir / "twin.yaml", "positioner: parallel\n");
    cli = test::spawn_cli(
        {"serve", "--config", (dir / "twin.yaml").string(), "--emulate", "gcs2-hexapod=127.0.0.1:0",
         "--listen", "127.0.0.1:0", "--out", (dir / "rec").string(), "--duration", "300"},
        dir / "twin");
    const std::regex re(R"(emulate gcs2-hexapod 127\.0\.0\.1:(\d+))");
    test::eventually(
        [&] {
          const std::string out = test::read_text(cli.out);
          std::smatch m;
          if (!std::regex_search(out, m, re)) return false;
          port = static_cast<std::uint16_t>(std::stoi(m[1]));
          return true;
        },
        60s);
  }
  void kill_now() {
    ::kill(cli.pid, SIGKILL);
    test::wait_process(cli.pid, 10s);
    alive = false;
  }
  ~HexapodTwinProcess() {
    if (!alive) return;
    ::kill(cli.pid, SIGINT);
    test::wait_process(cli.pid, 10s);
  }
};

// One query to the twin through its own GCS port, by a client of its own (a query takes no
// control): the reply's text, empty when it does not answer within 5 s.
std::string twin_query(std::uint16_t port, const std::string& line) {
  std::string text;
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0) {
    timeval tv{5, 0};
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    const std::string q = line + "\n";
    ::send(fd, q.data(), q.size(), MSG_NOSIGNAL);
    char buf[1024];
    while (!drivers::gcs2::reply_complete(text)) {
      const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
      if (n <= 0) break;
      text.append(buf, static_cast<std::size_t>(n));
    }
  }
  ::close(fd);
  return text;
}

// The twin's measured pose; NaN when it does not answer six axes.
Pose6 twin_pose(std::uint16_t port) {
  Pose6 out;
  out.fill(std::nan(""));
  const auto v = drivers::gcs2::parse_axis_values(twin_query(port, "POS? X Y Z U V W"));
  for (std::size_t i = 0; i < 6 && v.size() == 6; ++i) out[i] = v[i].second;
  return out;
}

motion::PlatformTransform transform_of(const Pose6& p) {
  return motion::to_transform(motion::PiPose{p[0] * 1e-3, p[1] * 1e-3, p[2] * 1e-3, p[3] * kRadPerDeg,
                                             p[4] * kRadPerDeg, p[5] * kRadPerDeg});
}

// A platform with the parallel positioner on `pi-hexapod` at the twin's port; the console holds
// the deadman (fresh, active) at every operator tick.
struct HexapodPlatform {
  std::unique_ptr<Platform> p;
  teleop::ConsoleInput in;
  /// `speed_m_s`: the moves' tool point speed (parallel_positioner.move.max_speed_m_s), sent as VLS.
  explicit HexapodPlatform(std::uint16_t port, double speed_m_s = motion::PoseMoveLimits{}.max_speed_m_s) {
    drivers::register_vendor_drivers();
    PlatformConfig c;
    c.positioner = "parallel";
    c.parallel_positioner.driver = "pi-hexapod";
    c.parallel_positioner.connection = fmt::format("127.0.0.1:{},timeout_s={},stale_s=0.5", port, kTimeout_s);
    c.parallel_positioner.move.max_speed_m_s = speed_m_s;
    p = platform::make_platform(c);
    in.active = in.fresh = in.deadman = true;
    const auto& s = p->config().stage;
    in.goal_m = {s.home_x_m, s.home_y_m, s.home_z_m};
    p->set_operator([this](const runtime::TickInfo&) { p->set_console_input(in); });
  }
  const devices::ParallelPositioner& positioner() const { return *p->positioner(); }
  // Runs the loop paced to the wall clock (10 ticks a ms) until `done` (checked every 10 ms) or
  // `timeout_s`; whether `done` held.
  template <class Done>
  bool run_until(double timeout_s, Done done) {
    const auto start = Clock::now();
    for (int ms = 0; ms < static_cast<int>(timeout_s * 1e3); ++ms) {
      p->loop().run_for(10);
      if (ms % 10 == 0 && done()) return true;
      std::this_thread::sleep_until(start + std::chrono::milliseconds(ms + 1));
    }
    return done();
  }
  // Plans and checks the move to `goal` from the held pose, and starts it (the loop's thread: this one).
  bool start(const Pose6& goal) {
    motion::PoseTrajectory t(positioner().reference_pose(), transform_of(goal),
                             p->config().parallel_positioner.move);
    const motion::MoveCheck c = motion::check_move(positioner().kinematics(), t);
    EXPECT_TRUE(c.ok) << c.reason;
    return c.ok && p->start_pose_move(t);
  }
};

TEST(DriverTwin, PiHexapodDrivesTheTwinInAnotherProcessThroughAPoseSequenceOnTarget) {
  HexapodTwinProcess twin;
  ASSERT_NE(twin.port, 0) << test::read_text(twin.cli.err);
  HexapodPlatform h(twin.port);
  ASSERT_TRUE(h.p->has_positioner());
  EXPECT_EQ(h.positioner().state(), devices::Lifecycle::kActive);
  EXPECT_NE(dynamic_cast<const drivers::PiHexapod*>(&h.positioner()), nullptr);
  ASSERT_TRUE(h.run_until(10.0, [&] { return h.positioner().at_rest(); }));
  const std::array<Pose6, 4> goals = {
      Pose6{0.03, -0.02, 0.01, 0, 0, 0}, Pose6{0.03, 0.01, 0.02, 0.1, -0.05, 0.2},
      Pose6{-0.02, 0.02, -0.01, -0.1, 0.08, -0.15}, Pose6{0.01, 0.0, 0.005, 0.05, 0.0, 0.1}};
  std::size_t allocations = 0;
  for (const Pose6& goal : goals) {
    ASSERT_TRUE(h.start(goal)) << "a move refused at rest";
    EXPECT_TRUE(h.positioner().moving());
    const auto start = Clock::now();
    bool there = false;
    {
      // The loop's thread (this one) while the positioner moves: nothing allocated.
      test::AllocationGuard guard(std::this_thread::get_id());
      there = h.run_until(30.0, [&] { return h.positioner().at_rest() || h.p->faulted(); });
      allocations += guard.allocations();
    }
    ASSERT_TRUE(there) << "not at rest in 30 s";
    ASSERT_FALSE(h.p->faulted()) << devices::to_string(h.positioner().state());
    const double s = std::chrono::duration<double>(Clock::now() - start).count();
    const Pose6 at = twin_pose(twin.port);
    const motion::PiPose measured = motion::to_pi(h.positioner().measured_pose());
    std::cout << fmt::format(
        "[ pi-hexapod -> twin ] goal ({:+.4f}, {:+.4f}, {:+.4f}) mm ({:+.3f}, {:+.3f}, {:+.3f}) deg: twin "
        "off by "
        "({:+.0f}, {:+.0f}, {:+.0f}) nm ({:+.1f}, {:+.1f}, {:+.1f}) udeg in {:.2f} s\n",
        goal[0], goal[1], goal[2], goal[3], goal[4], goal[5], (at[0] - goal[0]) * 1e6,
        (at[1] - goal[1]) * 1e6, (at[2] - goal[2]) * 1e6, (at[3] - goal[3]) * 1e6, (at[4] - goal[4]) * 1e6,
        (at[5] - goal[5]) * 1e6, s);
    // The twin's on-target tolerance: 1 um on X, Y, Z and 1 mdeg on U, V, W.
    for (std::size_t i = 0; i < 6; ++i)
      EXPECT_NEAR(at[i], goal[i], 1e-3) << "axis "
                                        << "XYZUVW"[i];
    // The platform measures the twin's pose (POS? through the driver), as the twin reads it.
    EXPECT_NEAR(measured.X * 1e3, at[0], 1e-3);
    EXPECT_NEAR(measured.W / kRadPerDeg, at[5], 1e-3);
    // Held: the goal itself, where the next move starts.
    EXPECT_LE((h.positioner().reference_pose().d - transform_of(goal).d).norm(), 1e-12);
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_EQ(static_cast<const drivers::PiHexapod&>(h.positioner()).controller().moves_sent(), goals.size());
}

TEST(DriverTwin, PiHexapodStopsTheTwinsMoveAndHoldsWhereItStopped) {
  HexapodTwinProcess twin;
  ASSERT_NE(twin.port, 0) << test::read_text(twin.cli.err);
  HexapodPlatform h(twin.port);
  ASSERT_TRUE(h.run_until(10.0, [&] { return h.positioner().at_rest(); }));
  // 0.2 mm at 0.1 mm/s: two seconds; stopped once under way (the twin's pose left home).
  ASSERT_TRUE(h.start({0.2, 0, 0, 0, 0, 0}));
  ASSERT_TRUE(h.run_until(10.0, [&] { return twin_pose(twin.port)[0] > 0.02; }));
  h.in.deadman = false;  // the platform stops the move the tick the deadman drops (#24)
  ASSERT_TRUE(h.run_until(10.0, [&] { return h.positioner().at_rest(); }));
  h.in.deadman = true;
  EXPECT_FALSE(h.p->faulted());
  const Pose6 stopped = twin_pose(twin.port);
  EXPECT_GT(stopped[0], 0.02);
  EXPECT_LT(stopped[0], 0.19);
  // It holds where it stopped: the pose the next move must start from.
  EXPECT_NEAR(h.positioner().reference_pose().d.x() * 1e3, stopped[0], 1e-3);
  h.run_until(0.3, [] { return false; });
  EXPECT_NEAR(twin_pose(twin.port)[0], stopped[0], 1e-3);
  // And moves again from there.
  ASSERT_TRUE(h.start({0.05, 0, 0, 0, 0, 0}));
  ASSERT_TRUE(h.run_until(30.0, [&] { return h.positioner().at_rest() || h.p->faulted(); }));
  EXPECT_FALSE(h.p->faulted());
  EXPECT_NEAR(twin_pose(twin.port)[0], 0.05, 1e-3);
}

TEST(DriverTwin, PiHexapodAStopWhileHoldingKeepsTheHeldPoseSoAMovePlannedFromItStarts) {
  // A vendor client's move is planned from the pose the platform published; the hand-over to that
  // client holds the platform first (Platform::hold: a stop). Holding already, the stop must not
  // hold again where the sensors read (a nanometre away): the planned move would not start.
  HexapodTwinProcess twin;
  ASSERT_NE(twin.port, 0) << test::read_text(twin.cli.err);
  HexapodPlatform h(twin.port);
  ASSERT_TRUE(h.run_until(10.0, [&] { return h.positioner().at_rest(); }));
  const motion::PlatformTransform held = h.positioner().reference_pose();
  motion::PoseTrajectory planned(held, transform_of({0.01, 0, 0, 0, 0, 0}),
                                 h.p->config().parallel_positioner.move);
  ASSERT_TRUE(motion::check_move(h.positioner().kinematics(), planned).ok);
  h.p->stop_pose_move();
  h.run_until(0.3, [] { return false; });  // bus cycles read the pose again meanwhile
  EXPECT_EQ(h.positioner().reference_pose().d, held.d);
  EXPECT_EQ(h.positioner().reference_pose().R, held.R);
  ASSERT_TRUE(h.p->start_pose_move(planned)) << "the move planned from the held pose did not start";
  ASSERT_TRUE(h.run_until(30.0, [&] { return h.positioner().at_rest() || h.p->faulted(); }));
  EXPECT_FALSE(h.p->faulted());
  EXPECT_NEAR(twin_pose(twin.port)[0], 0.01, 1e-3);
}

TEST(DriverTwin, PiHexapodTheEstopStopsTheTwinsMoveAndTheResetMovesAgain) {
  HexapodTwinProcess twin;
  ASSERT_NE(twin.port, 0) << test::read_text(twin.cli.err);
  HexapodPlatform h(twin.port);
  ASSERT_TRUE(h.run_until(10.0, [&] { return h.positioner().at_rest(); }));
  ASSERT_TRUE(h.start({0.2, 0, 0, 0, 0, 0}));
  ASSERT_TRUE(h.run_until(10.0, [&] { return twin_pose(twin.port)[0] > 0.02; }));
  h.p->fault_all();  // the operator's e-stop: every device's safe state, the hexapod's #24
  EXPECT_EQ(h.positioner().state(), devices::Lifecycle::kFault);
  ASSERT_TRUE(h.run_until(10.0, [&] { return !h.positioner().moving(); })) << "the stop never settled";
  const Pose6 stopped = twin_pose(twin.port);
  EXPECT_LT(stopped[0], 0.19);
  h.run_until(0.3, [] { return false; });
  EXPECT_NEAR(twin_pose(twin.port)[0], stopped[0], 1e-3);  // holding
  EXPECT_FALSE(h.start({0.0, 0, 0, 0, 0, 0}));             // refused until the reset
  h.p->recover();                                          // the bus stood: configured again as it is
  EXPECT_EQ(h.positioner().state(), devices::Lifecycle::kActive);
  ASSERT_TRUE(h.run_until(10.0, [&] { return h.positioner().at_rest(); }));
  ASSERT_TRUE(h.start({0.0, 0.02, 0, 0, 0, 0}));
  ASSERT_TRUE(h.run_until(30.0, [&] { return h.positioner().at_rest() || h.p->faulted(); }));
  EXPECT_FALSE(h.p->faulted());
  const Pose6 at = twin_pose(twin.port);
  EXPECT_NEAR(at[0], 0.0, 1e-3);
  EXPECT_NEAR(at[1], 0.02, 1e-3);
}

TEST(DriverTwin, PiHexapodAControllerErrorPutsThePlatformInItsSafeStateBeforeAnythingMoves) {
  HexapodTwinProcess twin;
  ASSERT_NE(twin.port, 0) << test::read_text(twin.cli.err);
  // 0.6 mm/s: within the legs' speed limit (the move passes check_move), above the twin's VLS
  // limit (0.5 mm/s): VLS is refused with error 8, and the MOV after it is never sent.
  HexapodPlatform h(twin.port, 0.6e-3);
  ASSERT_TRUE(h.run_until(10.0, [&] { return h.positioner().at_rest(); }));
  const Pose6 before = twin_pose(twin.port);
  ASSERT_TRUE(h.start({0.05, 0, 0, 0, 0, 0}));
  ASSERT_TRUE(h.run_until(5.0, [&] { return h.p->faulted(); }));
  EXPECT_EQ(h.positioner().state(), devices::Lifecycle::kFault);
  const auto& c = static_cast<const drivers::PiHexapod&>(h.positioner()).controller();
  EXPECT_EQ(c.fault_reason(), "'VLS 0.600000': controller error 8 (Velocity out of limits)");
  EXPECT_EQ(c.moves_sent(), 0u);
  h.run_until(0.3, [] { return false; });
  EXPECT_NEAR(twin_pose(twin.port)[0], before[0], 1e-3);  // nothing moved
}

// How the twin goes away mid-move.
enum class Death { kKilled, kFrozen };

// The twin goes away while the positioner moves: the platform is faulted (every device in its safe
// state) within one reply timeout and a move is refused; the reset then reconnects to a twin that
// answers again (frozen, then continued) and fails in one line on one that is gone (killed).
void expect_safe_within_one_timeout(Death death) {
  HexapodTwinProcess twin;
  ASSERT_NE(twin.port, 0) << test::read_text(twin.cli.err);
  HexapodPlatform h(twin.port);
  ASSERT_TRUE(h.run_until(10.0, [&] { return h.positioner().at_rest(); }));
  ASSERT_TRUE(h.start({0.2, 0, 0, 0, 0, 0}));
  ASSERT_TRUE(h.run_until(10.0, [&] { return twin_pose(twin.port)[0] > 0.01; }));
  ASSERT_TRUE(h.positioner().moving());
  if (death == Death::kKilled) {
    twin.kill_now();  // the connection reset: seen at the next reply
  } else {
    ::kill(twin.cli.pid, SIGSTOP);  // the connection stands, nothing answers: the reply timeout
  }
  const auto gone = Clock::now();
  const bool safe = h.run_until(5.0, [&] { return h.p->faulted(); });
  const double s = std::chrono::duration<double>(Clock::now() - gone).count();
  std::cout << fmt::format("[ pi-hexapod ] the twin {} mid-move: platform safe in {:.3f} s\n",
                           death == Death::kKilled ? "killed" : "frozen", s);
  if (death == Death::kFrozen) ::kill(twin.cli.pid, SIGCONT);
  ASSERT_TRUE(safe);
  // Within one reply timeout, plus the poll period and this loop's 10 ms between checks (a
  // sanitized loop runs slower than its pace).
  EXPECT_LT(s, kTimeout_s + (MC_UNDER_SANITIZER ? 0.3 : 0.1));
  EXPECT_EQ(h.positioner().state(), devices::Lifecycle::kFault);
  EXPECT_FALSE(h.positioner().moving());
  const auto& c = static_cast<const drivers::PiHexapod&>(h.positioner()).controller();
  EXPECT_TRUE(c.faulted());
  const std::string reason = c.fault_reason();
  if (death == Death::kKilled) {
    EXPECT_TRUE(reason.find("closed the connection") != std::string::npos ||
                reason.find("connection lost") != std::string::npos)
        << reason;
  } else {
    EXPECT_NE(reason.find("no reply within the timeout"), std::string::npos) << reason;
  }
  // Every device of the platform is in its safe state.
  for (int i = 0; i < 3; ++i) EXPECT_EQ(h.p->axis(i).state(), devices::Lifecycle::kFault);
  EXPECT_FALSE(h.start({0.0, 0, 0, 0, 0, 0}));  // a move is refused
  if (death == Death::kFrozen) {
    // The thawed twin first works through what the frozen connection still held: the query that
    // timed out, the driver's #24 and its ERR?, then the connection's close, which releases control
    // and may leave error 10. The operator resets once the controller is back; a close handled
    // after the reset's configure would leave its error to the reset's first move. Read here on a
    // side connection until the twin reports no error for a quarter of a second.
    const auto quiet_by = Clock::now() + 5s;
    int quiet = 0;  // errors 0 read in a row
    while (quiet < 5 && Clock::now() < quiet_by) {
      quiet = twin_query(twin.port, "ERR?").starts_with("0") ? quiet + 1 : 0;
      std::this_thread::sleep_for(50ms);
    }
    EXPECT_EQ(quiet, 5) << "the thawed twin still reports errors";
    // The twin answers again: the reset reconnects (the configure sequence again) and moves.
    h.p->recover();
    EXPECT_FALSE(h.p->faulted());
    EXPECT_EQ(h.positioner().state(), devices::Lifecycle::kActive);
    ASSERT_TRUE(h.run_until(10.0, [&] { return h.positioner().at_rest(); }));
    ASSERT_TRUE(h.start({0.05, 0.01, 0, 0, 0, 0.05}));
    ASSERT_TRUE(h.run_until(30.0, [&] { return h.positioner().at_rest() || h.p->faulted(); }));
    EXPECT_FALSE(h.p->faulted());
    const Pose6 at = twin_pose(twin.port);
    EXPECT_NEAR(at[0], 0.05, 1e-3);
    EXPECT_NEAR(at[1], 0.01, 1e-3);
    EXPECT_NEAR(at[5], 0.05, 1e-3);
    return;
  }
  // Nobody answers: the reset fails in one line naming the controller's address.
  try {
    h.p->recover();
    ADD_FAILURE() << "recovered without a controller";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(fmt::format("cannot connect to the controller at 127.0.0.1:{}", twin.port)),
              std::string::npos)
        << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(DriverTwin, PiHexapodPutsThePlatformInItsSafeStateWithinOneTimeoutWhenTheTwinIsKilledMidMove) {
  expect_safe_within_one_timeout(Death::kKilled);
}

TEST(DriverTwin,
     PiHexapodPutsThePlatformInItsSafeStateWithinOneTimeoutWhenTheTwinFreezesMidMoveAndReconnects) {
  expect_safe_within_one_timeout(Death::kFrozen);
}

}  // namespace pi_hexapod_driver_test
}  // namespace mc::twins
