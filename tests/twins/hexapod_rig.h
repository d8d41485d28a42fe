#pragma once
// The hexapod twin's rig: the live platform with the thesis's assembly (`positioner: parallel`),
// its loop paced, and the C-887 dialect over it through the live stage, asked line by line from
// the test's thread (the protocol thread's place, which also sends the controlling client's
// heartbeat before each line as the twin server does every 20 ms).

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "microcobot/drivers/gcs2_codec.h"
#include "microcobot/live/live_platform.h"
#include "microcobot/twins/gcs2_hexapod_twin.h"
#include "microcobot/twins/live_stage.h"

namespace mc::twins::testing {

/// The live platform's parameters with the parallel positioner carrying the part.
inline live::LiveParams hexapod_live_params(double command_timeout_s = 2.0) {
  live::LiveParams p;
  p.platform.positioner = "parallel";
  p.command_timeout_s = command_timeout_s;
  return p;
}

struct HexapodRig {
  live::LivePlatform live;
  LiveStage stage;
  Gcs2HexapodTwin twin;
  explicit HexapodRig(bool start = true, double command_timeout_s = 2.0)
      : live(hexapod_live_params(command_timeout_s)), stage(live), twin(stage, Gcs2HexapodTwinParams{}) {
    if (start) live.start([](const platform::TelemetrySample&, std::size_t) {});
  }
  ~HexapodRig() { live.stop(); }
  std::string ask(const std::string& line, ClientId c = 1) {
    stage.heartbeat();
    return twin.on_line(c, line);
  }
  std::string byte(char b) {
    stage.heartbeat();
    return twin.on_byte(1, b);
  }
  std::string err() { return ask("ERR?"); }
  /// Polls ONT? until every axis is on target (PIPython's waitontarget).
  bool wait_on_target(double timeout_s = 30.0) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < end) {
      if (ask("ONT? X") == "X=1\n") return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return false;
  }
  void reference() {
    ASSERT_EQ(ask("FRF"), "");
    ASSERT_EQ(err(), "0\n");
    ASSERT_TRUE(wait_on_target());
    ASSERT_EQ(ask("FRF? X"), "X=1\n");
  }
  /// X, Y, Z [mm], U, V, W [deg] of a POS? or MOV? reply.
  std::array<double, 6> pose(const std::string& query = "POS?") {
    std::array<double, 6> p{};
    const auto values = drivers::gcs2::parse_axis_values(ask(query));
    EXPECT_EQ(values.size(), 6u) << query;
    for (std::size_t i = 0; i < values.size() && i < 6; ++i) p[i] = values[i].second;
    return p;
  }
};

}  // namespace mc::twins::testing
