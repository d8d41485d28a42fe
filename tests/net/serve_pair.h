#pragma once
/// @file
/// Helpers of the tests that run `microcobot serve --role master|slave` as real processes: start
/// one and read its console's port, watch its telemetry through a console, drive the master's
/// console until a condition holds on both ends' telemetry.

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/console_client.h"
#include "support/test_support.h"

namespace mc::test {

/// Every process a test started is killed when the test ends, passed or failed.
struct Reaper {
  std::vector<pid_t> pids;
  ~Reaper() {
    for (pid_t p : pids) wait_process(p, std::chrono::milliseconds(0));  // already reaped: nothing happens
  }
};

/// A `serve` process and its console's port (read off the first line of its stdout).
struct Server {
  BackgroundCli process;
  std::uint16_t port = 0;
};

/// Starts `serve --role role --domain domain` with its console on a free loopback port, its
/// recordings and output under `dir/name`, and `extra` flags. `launcher` goes before the binary
/// (e.g. `ip netns exec NS`: it execs the binary, so the pid is the server's).
inline Server start_serve(const std::string& role, const std::string& domain, const TempDir& dir,
                          const std::string& name, Reaper& reaper, const std::vector<std::string>& extra = {},
                          const std::vector<std::string>& launcher = {}) {
  std::vector<std::string> argv = launcher;
  for (const std::string& a :
       {std::string(MC_CLI_PATH), std::string("serve"), std::string("--role"), role, std::string("--domain"),
        domain, std::string("--listen"), std::string("127.0.0.1:0"), std::string("--out"),
        (dir / name).string(), std::string("--duration"), std::string("300")})
    argv.push_back(a);
  argv.insert(argv.end(), extra.begin(), extra.end());
  Server s;
  s.process.out = (dir / name).string() + ".out";
  s.process.err = (dir / name).string() + ".err";
  s.process.pid = spawn_process(argv, s.process.out, s.process.err);
  reaper.pids.push_back(s.process.pid);
  std::string url;
  EXPECT_TRUE(eventually(
      [&] {
        url = read_text(s.process.out);
        return url.find('\n') != std::string::npos;
      },
      std::chrono::seconds(60)))
      << role << " did not print its URL: " << read_text(s.process.err);
  const auto colon = url.rfind(':');
  if (colon != std::string::npos) s.port = static_cast<std::uint16_t>(std::atoi(url.c_str() + colon + 1));
  return s;
}

/// SIGTERM to each server; each must exit 0 (every device in its safe state, recordings closed).
inline void terminate_cleanly(std::initializer_list<const Server*> servers) {
  for (const Server* s : servers) ::kill(s->process.pid, SIGTERM);
  for (const Server* s : servers)
    EXPECT_EQ(wait_process(s->process.pid, std::chrono::seconds(30)), 0) << read_text(s->process.err);
}

/// A console subscribed to the telemetry; `next()` reads the next telemetry message.
struct Watch {
  static constexpr std::uint32_t kTelemetrySub = 10;
  Console console;
  nlohmann::json last;
  /// The lowest lag seen between a frame's loop time (`t_s`) and its arrival here (s): the
  /// watched loop's clock on this process's steady clock, plus the fastest delivery. A loaded
  /// machine delivers the telemetry late (frames queue in the socket), so when a frame arrives
  /// says little about when the loop produced it; its `t_s` does.
  double min_lag_s = std::numeric_limits<double>::infinity();
  explicit Watch(std::uint16_t port) : console(port) {
    console.subscribe("/platform/telemetry", kTelemetrySub);
  }
  const nlohmann::json& next() {
    const std::string payload = console.next_on(kTelemetrySub);
    last = payload.empty() ? nlohmann::json() : nlohmann::json::parse(payload);
    const double t = last.is_object() ? last.value("t_s", std::numeric_limits<double>::quiet_NaN())
                                      : std::numeric_limits<double>::quiet_NaN();
    if (std::isfinite(t)) min_lag_s = std::min(min_lag_s, steady_s(std::chrono::steady_clock::now()) - t);
    return last;
  }
  /// The watched loop's time at `when`, early by the fastest delivery at most.
  double loop_time_at(std::chrono::steady_clock::time_point when) const { return steady_s(when) - min_lag_s; }
  static double steady_s(std::chrono::steady_clock::time_point when) {
    return std::chrono::duration<double>(when.time_since_epoch()).count();
  }
};

/// A telemetry value (NaN when the message or the key is missing).
inline double at(const nlohmann::json& t, const char* key) {
  return t.is_object() ? t.value(key, std::numeric_limits<double>::quiet_NaN())
                       : std::numeric_limits<double>::quiet_NaN();
}

/// Drives the master's console (a heartbeat at every telemetry frame, ~60 Hz) until `done`
/// holds on the telemetry of both ends (`slave` may be null: the master's only), or `timeout`
/// passes.
template <class Done>
bool drive(Watch& master, Watch* slave, const nlohmann::json& command, Done done,
           std::chrono::seconds timeout = std::chrono::seconds(30)) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  static const nlohmann::json none;
  while (std::chrono::steady_clock::now() < end) {
    master.console.command(command);
    if (master.next().is_null() || (slave && slave->next().is_null())) return false;
    if (done(master.last, slave ? slave->last : none)) return true;
  }
  return false;
}

/// The master's console command that holds the operator's deadman and jogs at `v` [m/s].
inline nlohmann::json jog(double vx, double vy = 0.0, double vz = 0.0) {
  return {{"deadman", true}, {"velocity_m_s", {vx, vy, vz}}};
}

}  // namespace mc::test
