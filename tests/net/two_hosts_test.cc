// The distributed platform on two hosts (the operator's desk and the microscope
// stage on different computers). One machine is all a test has, so the two hosts are two Linux network
// namespaces: each its own network stack (interfaces, addresses, routes, its own loopback), joined
// only by a virtual cable (a veth pair) with the addresses 198.18.0.1 (desk) and 198.18.0.2
// (bench), from RFC 2544's benchmarking range, which no real network routes. Each `serve` is told
// its own interface and its peer's address (--interface, --peer), as on two machines; the DDS
// traffic can only cross the cable, whose packet counters the test reads. Then the cable is
// pulled while the operator jogs, and plugged back.
//
// Needs root (creating namespaces): skipped otherwise; CI runs as root. Not run under the
// sanitizers, for the reason distributed_serve_test.cc gives (the asan preset excludes
// DistributedServe.* by name).

#include <fcntl.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "net/net_test_support.h"
#include "net/serve_pair.h"

namespace mc {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;
using test::at;
using test::drive;
using test::jog;
using test::Reaper;
using test::Server;
using test::start_serve;
using test::Watch;

constexpr const char* kDeskAddress = "198.18.0.1";
constexpr const char* kBenchAddress = "198.18.0.2";

std::string ip_program() {
  for (const char* p : {"/usr/sbin/ip", "/sbin/ip", "/usr/bin/ip", "/bin/ip"})
    if (::access(p, X_OK) == 0) return p;
  return {};
}

/// Two network namespaces joined by a veth pair, removed (with the pair) on destruction.
class TwoHosts {
 public:
  enum Host { kDesk, kBench };

  TwoHosts() : ip_(ip_program()) {
    const std::string id = std::to_string(::getpid() % 100000);
    names_ = {"mcdesk" + id, "mcbench" + id};
    if (ip_.empty()) {
      why_ = "no `ip` program (iproute2)";
      return;
    }
    if (!ip({"netns", "add", names_[kDesk]}) || !ip({"netns", "add", names_[kBench]})) {
      why_ = "cannot create network namespaces: " + error_;
      return;
    }
    ok_ = ip({"link", "add", names_[kDesk], "type", "veth", "peer", "name", names_[kBench]}) &&
          ip({"link", "set", names_[kDesk], "netns", names_[kDesk]}) &&
          ip({"link", "set", names_[kBench], "netns", names_[kBench]}) &&
          ip({"-n", names_[kDesk], "addr", "add", std::string(kDeskAddress) + "/30", "dev", names_[kDesk]}) &&
          ip({"-n", names_[kBench], "addr", "add", std::string(kBenchAddress) + "/30", "dev",
              names_[kBench]}) &&
          ip({"-n", names_[kDesk], "link", "set", "lo", "up"}) &&
          ip({"-n", names_[kBench], "link", "set", "lo", "up"}) && cable(true);
    if (!ok_) why_ = "cannot lay the cable between the namespaces: " + error_;
  }
  ~TwoHosts() {
    for (const std::string& n : names_)
      if (!ip_.empty()) ip({"netns", "del", n});
  }
  TwoHosts(const TwoHosts&) = delete;
  TwoHosts& operator=(const TwoHosts&) = delete;

  bool ok() const { return ok_; }
  const std::string& why() const { return why_; }

  /// What runs a program on `host` (`ip netns exec` execs it: the pid stays the program's).
  std::vector<std::string> launcher(Host host) const { return {ip_, "netns", "exec", names_[host]}; }

  /// Plugs (both ends up) or pulls (the bench's end down: the desk's loses its carrier) the cable.
  bool cable(bool plugged) {
    const char* state = plugged ? "up" : "down";
    return ip({"-n", names_[kBench], "link", "set", names_[kBench], state}) &&
           (!plugged || ip({"-n", names_[kDesk], "link", "set", names_[kDesk], "up"}));
  }

  /// Packets the desk's end of the cable has sent and received.
  std::pair<double, double> desk_packets() {
    test::TempDir tmp;
    const pid_t pid =
        test::spawn_process({ip_, "-n", names_[kDesk], "-s", "-j", "link", "show", "dev", names_[kDesk]},
                            tmp / "out", tmp / "err");
    if (test::wait_process(pid, 10s) != 0)
      return {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
    const json j = json::parse(test::read_text(tmp / "out"), nullptr, false);
    if (!j.is_array() || j.empty() || !j[0].contains("stats64"))
      return {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
    const json& s = j[0]["stats64"];
    return {s["tx"]["packets"].get<double>(), s["rx"]["packets"].get<double>()};
  }

  /// Calls `make()` on a thread that entered `host`'s network stack, so that the sockets it opens
  /// (a console's connection to that host's 127.0.0.1) live there; returns what it made.
  template <class Make>
  auto on(Host host, Make make) -> decltype(make()) {
    decltype(make()) made{};
    std::thread([&] {
      const int fd = ::open(("/run/netns/" + names_[host]).c_str(), O_RDONLY | O_CLOEXEC);
      ASSERT_GE(fd, 0) << "cannot open " << names_[host];
      ASSERT_EQ(::setns(fd, CLONE_NEWNET), 0) << "cannot enter " << names_[host];
      ::close(fd);
      made = make();
    }).join();
    return made;
  }

 private:
  bool ip(const std::vector<std::string>& args) {
    test::TempDir tmp;
    std::vector<std::string> argv{ip_};
    argv.insert(argv.end(), args.begin(), args.end());
    const pid_t pid = test::spawn_process(argv, tmp / "out", tmp / "err");
    if (test::wait_process(pid, 10s) == 0) return true;
    error_ = test::read_text(tmp / "err");
    return false;
  }

  std::string ip_;
  std::array<std::string, 2> names_;
  bool ok_ = false;
  std::string why_, error_;
};

TEST(DistributedServe, OnTwoHostsJoinedByACableThatIsPulledAndPluggedBack) {
  if (::geteuid() != 0) GTEST_SKIP() << "network namespaces need root";
  TwoHosts hosts;
  if (!hosts.ok()) GTEST_SKIP() << hosts.why();
  test::TempDir dir;
  Reaper reaper;
  const std::string domain = std::to_string(net::test::test_domain_id());
  Server bench =
      start_serve("slave", domain, dir, "bench", reaper,
                  {"--interface", kBenchAddress, "--peer", kDeskAddress}, hosts.launcher(TwoHosts::kBench));
  Server desk =
      start_serve("master", domain, dir, "desk", reaper,
                  {"--interface", kDeskAddress, "--peer", kBenchAddress}, hosts.launcher(TwoHosts::kDesk));
  ASSERT_NE(bench.port, 0);
  ASSERT_NE(desk.port, 0);
  // Each console is reached on its own host's loopback.
  auto m = hosts.on(TwoHosts::kDesk, [&] { return std::make_unique<Watch>(desk.port); });
  auto s = hosts.on(TwoHosts::kBench, [&] { return std::make_unique<Watch>(bench.port); });
  ASSERT_TRUE(m && s);
  ASSERT_TRUE(m->console.action("take_control"));
  const json hold = jog(0.0);
  ASSERT_TRUE(drive(
      *m, s.get(), hold, [](const json& mt, const json&) { return at(mt, "engaged") == 1.0; }, 60s))
      << "the desk never engaged the bench: " << m->last.dump() << "\n"
      << test::read_text(desk.process.err);

  // 1. The operator at the desk jogs +x at 100 um/s: the stage on the bench follows.
  const double x0 = at(s->last, "measured_x_m");
  ASSERT_TRUE(drive(*m, s.get(), jog(100e-6),
                    [&](const json&, const json& st) { return at(st, "measured_x_m") > x0 + 50e-6; }))
      << "the bench did not follow: " << s->last.dump();
  ASSERT_TRUE(drive(*m, s.get(), hold, [](const json& mt, const json& st) {
    return std::abs(at(mt, "measured_x_m") - at(st, "measured_x_m")) < 2e-6;
  })) << "the desk does not see where the bench is";

  // 2. The link crosses the cable: about a second of holding, both ways at the loop's rate (each
  //    side publishes its 1 kHz state topics, one datagram per sample).
  const auto [sent0, received0] = hosts.desk_packets();
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 60; ++i) drive(*m, s.get(), hold, [](const json&, const json&) { return true; });
  const auto [sent1, received1] = hosts.desk_packets();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double sent_per_s = (sent1 - sent0) / seconds, received_per_s = (received1 - received0) / seconds;
  std::printf("the cable carried %.0f packets/s desk -> bench, %.0f bench -> desk over %.2f s\n", sent_per_s,
              received_per_s, seconds);
  EXPECT_GT(sent_per_s, 500.0) << "the desk's targets do not cross the cable";
  EXPECT_GT(received_per_s, 500.0) << "the bench's state does not cross the cable";

  // 3. The cable is pulled while the operator jogs: the desk disengages with zero force on the
  //    hands and the tweezers' fingers (its slave fell silent), the bench disengages and its stage holds (its
  //    master did). Frames are judged by when each loop produced them (Watch::loop_time_at): on a
  //    loaded machine the telemetry arrives late, and frames from before the pull still come in
  //    after it. From 50 ms after the pull (the 8 ms timeouts, DDS's 10 ms deadline, the fastest
  //    delivery the clock mapping may miss) nothing may be engaged.
  ASSERT_TRUE(hosts.cable(false));
  const auto pulled = std::chrono::steady_clock::now();
  const double desk_pulled_t = m->loop_time_at(pulled), bench_pulled_t = s->loop_time_at(pulled);
  const auto since_pull_s = [&](const json& mt, const json& st) {
    return std::min(at(mt, "t_s") - desk_pulled_t, at(st, "t_s") - bench_pulled_t);
  };
  ASSERT_TRUE(drive(*m, s.get(), jog(100e-6),
                    [&](const json& mt, const json& st) {
                      return since_pull_s(mt, st) >= 0.0 && at(mt, "engaged") == 0.0 &&
                             at(st, "engaged") == 0.0;
                    }))
      << "engaged across a pulled cable: desk " << m->last.dump() << "\nbench " << s->last.dump();
  std::printf("both ends disengaged on the first frames %.0f ms (loop time) after the pull (60 Hz frames)\n",
              1e3 * since_pull_s(m->last, s->last));
  double held = std::numeric_limits<double>::quiet_NaN();
  int resting = 0;
  ASSERT_TRUE(drive(*m, s.get(), jog(100e-6),
                    [&](const json& mt, const json& st) {
                      if (since_pull_s(mt, st) < 0.05) return false;
                      EXPECT_EQ(at(mt, "engaged"), 0.0) << "the desk re-engaged without a cable";
                      EXPECT_EQ(at(st, "engaged"), 0.0) << "the bench re-engaged without a cable";
                      for (const char* f : {"haptic_force_x_N", "haptic_force_y_N", "finger_force_N"})
                        EXPECT_EQ(at(mt, f), 0.0) << f << " on the operator's hand without a slave";
                      const double x = at(st, "measured_x_m");
                      resting = std::abs(x - held) < 1e-6 ? resting + 1 : (held = x, 0);
                      return resting >= 30;
                    }))
      << "the bench must hold where it was: " << s->last.dump();
  // Out for less than the participants' lease (10 s): the peers keep each other and only the
  // samples stop, as when a cable is pulled and plugged back at once.
  const double outage_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - pulled).count();
  EXPECT_LT(outage_s, 8.0);

  // 4. The operator stops jogging (deadman still held) and the cable is plugged back: the desk
  //    re-engages where the bench stands, without a jump. (A jog held through the plug resumes at
  //    once, from where the bench stands, at the jog's speed: the deadman is held.)
  for (int i = 0; i < 5; ++i) drive(*m, s.get(), hold, [](const json&, const json&) { return true; });
  ASSERT_TRUE(hosts.cable(true));
  int frames_to_engage = 0;
  ASSERT_TRUE(drive(
      *m, s.get(), hold,
      [&](const json& mt, const json&) {
        ++frames_to_engage;
        return at(mt, "engaged") == 1.0;
      },
      60s))
      << "the desk never re-engaged: " << m->last.dump();
  std::printf("cable out %.2f s; the desk engaged on telemetry frame %d after it was plugged back\n",
              outage_s, frames_to_engage);
  int frames = 0;
  ASSERT_TRUE(drive(*m, s.get(), hold, [&](const json& mt, const json& st) {
    EXPECT_NEAR(at(st, "measured_x_m"), held, 2e-6) << "the bench jumped on re-engagement";
    EXPECT_NEAR(at(mt, "target_x_m"), at(mt, "measured_x_m"), 2e-6);
    return ++frames >= 30;
  }));
  // And the operator drives it again.
  ASSERT_TRUE(drive(*m, s.get(), jog(-100e-6),
                    [&](const json&, const json& st) { return at(st, "measured_x_m") < held - 20e-6; }))
      << "the bench did not follow after the cable came back: " << s->last.dump();

  m.reset();
  s.reset();
  test::terminate_cleanly({&desk, &bench});
}

}  // namespace
}  // namespace mc
