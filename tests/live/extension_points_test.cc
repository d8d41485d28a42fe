// What a caller adds to the live platform in one place reaches the loop and every output:
// - a command source (LiveParams::sources) is polled on the loop, drives the coupling when the
//   arbiter gives it control, yields to a console user, and moves nothing under the e-stop; the
//   status names it;
// - a telemetry channel (LiveParams::telemetry_channels) appears, with its name and unit, in the
//   live server's Foxglove schema and messages, the MCAP recording's schema and messages and the
//   CSV recording's header and rows (tests/python/test_added_channel.py reads the same files
//   through the Python module).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "microcobot/core/csv.h"
#include "microcobot/core/mcap_reader.h"
#include "microcobot/live/console_server.h"
#include "microcobot/live/live_platform.h"
#include "microcobot/platform/telemetry_json.h"
#include "microcobot/server/foxglove_protocol.h"
#include "support/live_status_wait.h"
#include "support/test_support.h"
#include "support/ws_client.h"

namespace mc::live {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr const char* kProbe = "probe_x_m";

// A caller's input: asks for control while `active`, and then jogs x at 100 um/s with its own
// deadman held.
class JogSource final : public CommandSource {
 public:
  static constexpr double kSpeed_m_s = 100e-6;
  std::atomic<bool> active{false};
  std::atomic<std::uint64_t> polls{0};

  std::string_view name() const noexcept override { return "jog"; }
  SourceRequest poll(const SourceTick&) noexcept override {
    polls.fetch_add(1, std::memory_order_relaxed);
    return {active.load(std::memory_order_relaxed) ? Claim::kActive : Claim::kNone};
  }
  void drive(const SourceTick&, teleop::ConsoleInput& in) noexcept override {
    in.active = in.fresh = in.deadman = true;
    in.velocity_m_s = {kSpeed_m_s, 0.0, 0.0};
  }
};

TEST(AddedSource, DrivesWhenGivenControlYieldsToTheConsoleAndMovesNothingUnderTheEstop) {
  JogSource jog;
  LiveParams lp;
  lp.sources.push_back(&jog);
  LivePlatform live(lp);
  const std::size_t x = test::telemetry_channel("measured_x_m");
  std::atomic<double> x_m{0.0};
  std::atomic<std::uint64_t> samples{0};
  live.start([&](const platform::TelemetrySample& s, std::size_t) {
    x_m.store(s[x]);
    samples.fetch_add(1);
  });
  // Waits for `n` more telemetry samples (1 kHz of loop time): the loop ran that long.
  auto run_for = [&](std::uint64_t n) {
    const std::uint64_t until = samples.load() + n;
    return test::wait_status(
        live, [&](const LiveStatus&) { return samples.load() >= until; }, 60.0);
  };
  auto control_is = [&](const std::string& who) {
    return test::wait_status(
        live, [&](const LiveStatus& s) { return s.control == who; }, 60.0);
  };
  // Polled on the loop from the start; not asking, so the console (on standby) holds the stage.
  ASSERT_TRUE(control_is("console"));
  EXPECT_GT(jog.polls.load(), 0u);
  const double x0 = x_m.load();

  jog.active = true;
  ASSERT_TRUE(control_is("jog"));
  ASSERT_TRUE(test::wait_status(
      live, [&](const LiveStatus&) { return x_m.load() - x0 > 10e-6; }, 60.0))
      << "the source's jog moved x by " << 1e6 * (x_m.load() - x0) << " um";

  // A console user takes control: the console outranks the source, the stage holds.
  live.set_console_in_control(true);
  ASSERT_TRUE(control_is("console"));
  ASSERT_TRUE(run_for(100));  // the hold settles
  const double held = x_m.load();
  ASSERT_TRUE(run_for(300));
  EXPECT_NEAR(x_m.load(), held, 0.5e-6) << "held while the console has control (its commands are stale)";

  // Released: the source drives again.
  live.set_console_in_control(false);
  ASSERT_TRUE(control_is("jog"));
  ASSERT_TRUE(test::wait_status(
      live, [&](const LiveStatus&) { return x_m.load() - held > 10e-6; }, 60.0));

  // The e-stop: every device to its safe state while the source still asks; nothing moves.
  live.estop();
  ASSERT_TRUE(test::wait_status(
      live, [](const LiveStatus& s) { return s.estopped; }, 60.0));
  ASSERT_TRUE(run_for(50));
  const double stopped = x_m.load();
  ASSERT_TRUE(run_for(300));
  EXPECT_NEAR(x_m.load(), stopped, 20e-9) << "the axes at 0 V";
  EXPECT_EQ(live.status().control, "jog");
  live.stop();
}

// Axis x's position from its home, as its sensor measures it: the built-in measured_x_m less
// the home's x, sampled at the same tick.
LiveParams::AddedChannel probe_channel() {
  return {{kProbe, "m", "axis x from its home, as its sensor measures it"},
          [](const platform::Platform& p) { return p.axis(0).position_m(); }};
}

TEST(AddedChannel, ReachesTheLiveSchemaTheMessagesTheMcapAndTheCsvWithItsUnit) {
  test::TempDir dir;
  LiveParams lp;
  lp.telemetry_channels.push_back(probe_channel());
  LivePlatform live(lp);
  const std::size_t probe = live.telemetry_schema().index(kProbe);
  EXPECT_EQ(probe, platform::builtin_telemetry(true).size()) << "after the built-in channels";
  ConsoleServerParams sp;
  sp.server.port = 0;
  sp.out_dir = dir.path();
  sp.record_csv = true;
  ConsoleServer server(live, sp);
  server.start();

  // The live schema: the channel with its unit and description.
  test::WsClient ws;
  ASSERT_EQ(ws.connect(server.port()), 101);
  json telemetry;
  for (int i = 0; i < 20 && telemetry.is_null(); ++i) {
    const json j = ws.read_json();
    ASSERT_FALSE(j.is_null()) << "no advertisement";
    if (j.value("op", "") == "advertise")
      for (const auto& c : j["channels"])
        if (c["topic"] == "/platform/telemetry") telemetry = c;
  }
  ASSERT_FALSE(telemetry.is_null());
  const json live_schema = json::parse(telemetry["schema"].get<std::string>());
  ASSERT_TRUE(live_schema["properties"].contains(kProbe)) << live_schema.dump();
  EXPECT_EQ(live_schema["properties"][kProbe]["unit"], "m");
  EXPECT_NE(live_schema["properties"][kProbe]["description"].get<std::string>().find("axis x from its home"),
            std::string::npos);

  // The live messages carry it, and the recording runs meanwhile.
  const std::string name = server.start_recording();
  ASSERT_TRUE(
      ws.send_json({{"op", "subscribe"}, {"subscriptions", {{{"id", 1}, {"channelId", telemetry["id"]}}}}}));
  double first_t = -1.0, t = -1.0;
  for (int i = 0; i < 100000 && (first_t < 0.0 || t - first_t < 0.3); ++i) {
    const auto m = ws.read();
    ASSERT_TRUE(m) << "the telemetry stopped";
    if (m->text) continue;
    const auto d = server::decode_message_data(m->data);
    const auto* md = std::get_if<server::MessageData>(&d);
    if (md == nullptr || md->subscription != 1) continue;
    const json j = json::parse(md->payload);
    ASSERT_TRUE(j.contains(kProbe)) << j.dump();
    t = j["t_s"].get<double>();
    if (first_t < 0.0) first_t = t;
  }
  server.stop_recording();
  server.stop();

  // The MCAP recording: its schema declares the channel and its unit; every message has it.
  const McapContents mcap = read_mcap(dir / name);
  const platform::TelemetrySchema recorded = platform::telemetry_schema_from_mcap(mcap, name);
  EXPECT_EQ(recorded, live.telemetry_schema());
  EXPECT_EQ(recorded[recorded.index(kProbe)].unit, "m");
  const Recorder rec = platform::telemetry_from_mcap(mcap, name, 1u << 20);
  ASSERT_GT(rec.size(), 100u);

  // The CSV recording: the same columns, and the channel is what its source reads, sampled at
  // the same tick as the built-in ones (measured_x_m - probe_x_m is the home's x in every row).
  const std::string stem = name.substr(0, name.size() - 5);
  const CsvTable csv = read_csv(dir / (stem + ".csv"));
  EXPECT_EQ(csv.names(), live.telemetry_schema().names());
  ASSERT_EQ(csv.rows(), rec.size());
  const auto measured = csv.column("measured_x_m"), probe_x = csv.column(kProbe);
  const double home_x = measured[0] - probe_x[0];
  EXPECT_GT(std::abs(home_x), 1e-6) << "the home is not at the origin: the test tells them apart";
  for (std::size_t i = 0; i < csv.rows(); ++i)
    ASSERT_NEAR(measured[i] - probe_x[i], home_x, 1e-12) << "row " << i;

  // For the Python side of the test: the files, where it asked for them.
  if (const char* out = std::getenv("MC_ADDED_CHANNEL_OUT")) {
    fs::create_directories(out);
    fs::copy_file(dir / name, fs::path(out) / "recording.mcap", fs::copy_options::overwrite_existing);
    fs::copy_file(dir / (stem + ".csv"), fs::path(out) / "recording.csv",
                  fs::copy_options::overwrite_existing);
  }
}

TEST(AddedChannel, ARefusedChannelLeavesNothingBuilt) {
  LiveParams lp;
  lp.telemetry_channels.push_back(
      {{"probe_x", "m", "no unit suffix"}, [](const platform::Platform&) { return 0.0; }});
  EXPECT_THROW(LivePlatform{lp}, InvalidParams);
  lp.telemetry_channels = {
      {{"measured_x_m", "m", "a built-in name"}, [](const platform::Platform&) { return 0.0; }}};
  EXPECT_THROW(LivePlatform{lp}, InvalidParams);
  lp.telemetry_channels = {{{"probe_x_m", "m", "no source"}, nullptr}};
  EXPECT_THROW(LivePlatform{lp}, InvalidParams);
}

}  // namespace
}  // namespace mc::live
