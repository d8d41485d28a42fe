#pragma once
// The vendor twins' live rig: a blocking loopback client and the live platform with
// both twins served on loopback port 0.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "microcobot/drivers/gcs2_codec.h"
#include "microcobot/live/live_platform.h"
#include "microcobot/twins/live_stage.h"
#include "microcobot/twins/twin_server.h"
#include "support/live_status_wait.h"

namespace mc::twins::testing {

using namespace std::chrono_literals;

/// The live platform's parameters for a twin served over TCP. The twin server's thread sends the
/// controlling client's heartbeat every 20 ms; the platform's default timeout (0.2 s) holds the
/// stage when that thread is starved longer, which a loaded machine running the sanitizers does,
/// rightly stopping a move short. The rigs give the heartbeat 2 s, so that a test sees the protocol's
/// own behaviour; a disconnect still holds the stage at once (the twin releases it), and the stale
/// heartbeat has its own tests with the default.
inline live::LiveParams twin_live_params() {
  live::LiveParams p;
  p.command_timeout_s = 2.0;
  return p;
}

// A blocking loopback TCP client with a receive timeout.
struct Client {
  int fd = -1;
  explicit Client(std::uint16_t port, double timeout_s = 3.0) {
    fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) throw std::runtime_error("connect");
    timeval tv{static_cast<time_t>(timeout_s), static_cast<suseconds_t>(std::fmod(timeout_s, 1.0) * 1e6)};
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  }
  ~Client() {
    if (fd >= 0) ::close(fd);
  }
  void send(const std::string& s) const {
    std::size_t done = 0;
    while (done < s.size()) {
      const ssize_t n = ::send(fd, s.data() + done, s.size() - done, MSG_NOSIGNAL);
      if (n <= 0) return;
      done += static_cast<std::size_t>(n);
    }
  }
  /// Reads until `done(text)` or the timeout / EOF; returns what came.
  template <class Done>
  std::string read_until(Done done) const {
    std::string text;
    char buf[4096];
    while (!done(text)) {
      const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
      if (n <= 0) break;
      text.append(buf, static_cast<std::size_t>(n));
    }
    return text;
  }
  std::string gcs(const std::string& line) const {
    send(line + "\n");
    return read_until([](const std::string& t) { return drivers::gcs2::reply_complete(t); });
  }
  /// Logs in to the ANC300 twin's console with its default password, up to its prompt.
  void anc300_login() const {
    read_until([](const std::string& t) { return t.find("code: ") != std::string::npos; });
    send("123456\r\n");
    read_until([](const std::string& t) { return t.find("> ") != std::string::npos; });
  }
  /// True once the server closed the connection (EOF) within the timeout.
  bool closed_by_server() const {
    char buf[4096];
    for (;;) {
      const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
      if (n == 0) return true;
      if (n < 0) return false;
    }
  }
};

// The live platform (paced loop) with both twins on loopback port 0; the rotary axis' sensor as
// the platform's telemetry reports it (not through the twins).
struct TwinRig {
  live::LiveParams params = twin_live_params();
  std::unique_ptr<live::LivePlatform> live;
  std::unique_ptr<LiveStage> stage;
  std::unique_ptr<TwinServer> server;
  std::atomic<double> theta_rad{std::nan("")};
  explicit TwinRig(double line_timeout_s = 5.0) {
    live = std::make_unique<live::LivePlatform>(params);
    const std::size_t yaw = test::telemetry_channel("measured_theta_rad");
    live->start([this, yaw](const platform::TelemetrySample& s, std::size_t) { theta_rad.store(s[yaw]); });
    stage = std::make_unique<LiveStage>(*live);
    TwinServerParams tp;
    tp.endpoints = {{Protocol::kGcs2, "127.0.0.1", 0}, {Protocol::kAnc300, "127.0.0.1", 0}};
    tp.line_timeout_s = line_timeout_s;
    tp.max_clients = 8;
    server = std::make_unique<TwinServer>(*stage, tp);
    server->start();
  }
  ~TwinRig() {
    server->stop();
    live->stop();
  }
  /// The rotary axis' angle in the telemetry, once a sample has reached it (the drain thread, which a
  /// sanitizer on a loaded machine may leave behind by seconds); NaN after `timeout_s` without one.
  double logged_theta_rad(double timeout_s = 10.0) const {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::isnan(theta_rad.load()) && std::chrono::steady_clock::now() < end)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    return theta_rad.load();
  }
  std::uint16_t gcs_port() const { return server->ports()[0]; }
  std::uint16_t anc_port() const { return server->ports()[1]; }
  double x_mm(const Client& c) const {
    return drivers::gcs2::parse_axis_values(c.gcs("POS? 1")).at(0).second;
  }
  void reference(const Client& c) const {
    // X, Y, Z (a bare FRF would name theta too, whose servo is off: error 5).
    c.send("SVO 1 1\nSVO 2 1\nSVO 3 1\nVEL 1 1\nVEL 2 1\nVEL 3 1\nFRF 1 2 3\n");
    wait_on_target(c, 5.0);
    ASSERT_EQ(c.gcs("FRF? 1 2 3"), "1=1 \n2=1 \n3=1\n");
  }
  static bool wait_on_target(const Client& c, double timeout_s) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < end) {
      if (c.gcs("ONT? 1 2 3") == "1=1 \n2=1 \n3=1\n") return true;
      std::this_thread::sleep_for(10ms);
    }
    return false;
  }
};

}  // namespace mc::twins::testing
