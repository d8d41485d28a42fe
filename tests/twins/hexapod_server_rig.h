#pragma once
// The hexapod twin served over TCP (loopback, port 0) on the live platform with the parallel
// positioner (the thesis's assembly), its loop paced; the helpers of a GCS client of it.

#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <thread>

#include "hexapod_rig.h"
#include "microcobot/drivers/gcs2_codec.h"
#include "microcobot/twins/twin_server.h"
#include "twin_rig.h"

namespace mc::twins::testing {

struct HexapodServerRig {
  std::unique_ptr<live::LivePlatform> live;
  std::unique_ptr<LiveStage> stage;
  std::unique_ptr<TwinServer> server;
  /// The largest leg voltage of the last telemetry sample (channel positioner_u_max_V).
  std::atomic<double> u_max_V{std::nan("")};
  explicit HexapodServerRig(double line_timeout_s = 5.0) {
    live = std::make_unique<live::LivePlatform>(hexapod_live_params(twin_live_params().command_timeout_s));
    const std::size_t u = live->telemetry_schema().index("positioner_u_max_V");
    live->start([this, u](const platform::TelemetrySample& s, std::size_t) { u_max_V.store(s[u]); });
    stage = std::make_unique<LiveStage>(*live);
    TwinServerParams tp;
    tp.endpoints = {{Protocol::kGcs2Hexapod, "127.0.0.1", 0}};
    tp.line_timeout_s = line_timeout_s;
    tp.max_clients = 8;
    server = std::make_unique<TwinServer>(*stage, tp);
    server->start();
  }
  ~HexapodServerRig() {
    server->stop();
    live->stop();
  }
  std::uint16_t port() const { return server->ports()[0]; }
};

inline std::string byte_reply(const Client& c, char b) {
  c.send(std::string(1, b));
  return c.read_until([](const std::string& t) { return !t.empty() && t.back() == '\n'; });
}

inline bool wait_on_target(const Client& c, double timeout_s = 30.0) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < end) {
    if (c.gcs("ONT? X Y Z U V W") == "X=1 \nY=1 \nZ=1 \nU=1 \nV=1 \nW=1\n") return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

inline double axis(const Client& c, const std::string& query) {
  return drivers::gcs2::parse_axis_values(c.gcs(query)).at(0).second;
}

inline void reference(const Client& c) {
  c.send("FRF X Y Z U V W\n");
  ASSERT_EQ(c.gcs("ERR?"), "0\n");
  ASSERT_TRUE(wait_on_target(c));
  ASSERT_EQ(c.gcs("FRF?"), "X=1 \nY=1 \nZ=1 \nU=1 \nV=1 \nW=1\n");
}

}  // namespace mc::twins::testing
