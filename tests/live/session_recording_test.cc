// The recording of a live session: every channel with wall-clock log times that
// never go back, events, metadata, the optional CSV; and nothing left when writing fails.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <map>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/core/mcap_reader.h"
#include "microcobot/live/session_recording.h"
#include "support/test_support.h"

namespace mc::live {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using ::testing::HasSubstr;

constexpr std::size_t kChannels = 20;

SessionRecordingParams params(const fs::path& dir, bool csv) {
  SessionRecordingParams p;
  p.out_dir = dir;
  p.csv = csv;
  p.telemetry = platform::builtin_telemetry(true).first(kChannels);
  const std::string object = R"({"type":"object"})";
  p.status = {"/platform/status", "microcobot.Status", object};
  p.scene = {"/platform/scene", "microcobot.Scene", object};
  p.feedback = {"/console/feedback", "microcobot.Feedback", object};
  p.version = "microcobot 9.9.9";
  p.config_yaml = "loop:\n  base_rate_Hz: 10000\n";
  return p;
}

platform::TelemetrySample sample(double t_s) {
  platform::TelemetrySample s{};
  s[0] = t_s;
  for (std::size_t c = 1; c < kChannels; ++c) s[c] = 1e-6 * static_cast<double>(c) + t_s;
  return s;
}

std::uint64_t now_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

TEST(SessionRecording, HoldsEveryChannelOnTheWallClockWithEventsAndMetadata) {
  test::TempDir dir;
  SessionRecording rec(params(dir.path(), false));
  const std::uint64_t before = now_ns();
  const std::string name = rec.start(100.0, R"({"kind":"pick-place","tolerance_m":5e-6})");
  EXPECT_TRUE(SessionRecording::is_stem(name.substr(0, name.size() - 5)));
  EXPECT_EQ(rec.name(), name);
  EXPECT_EQ(rec.start(100.0, "{}"), name);  // already recording
  for (int i = 0; i < 1500; ++i) rec.telemetry(sample(100.0 + 0.001 * i), kChannels);
  rec.published(RecordedTopic::kStatus, 100.2, R"({"t_s":100.2,"demo":false})");
  rec.published(RecordedTopic::kScene, 100.2, R"({"kind":"pick-place"})");
  rec.received(RecordedTopic::kAction, 3, 100.3, R"({"action":"take_control"})");
  rec.received(RecordedTopic::kCommand, 3, 100.4, "{not json");
  rec.event(EventLevel::kInfo, "take_control", "control: granted", 3, 100.3);
  rec.event(EventLevel::kError, "refused", "late", 4, 100.1);  // stamped before the previous one
  rec.stop();
  rec.stop();  // idempotent
  const std::uint64_t after = now_ns();
  EXPECT_EQ(rec.name(), "");
  ASSERT_EQ(fs::directory_iterator(dir.path())->path().filename(), name);  // alone: no CSV, no temporary
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator{}), 1);

  const McapContents m = read_mcap(dir / name);
  std::map<std::string, std::uint16_t> ids;
  for (const auto& c : m.channels) ids[c.topic] = c.id;
  for (const char* t : {"/platform/telemetry", "/platform/status", "/platform/scene", "/console/feedback",
                        "/console/command", "/console/action", "/events"})
    EXPECT_EQ(ids.count(t), 1u) << t;
  for (const auto& c : m.chunks) EXPECT_EQ(c.compression, "zstd");
  std::map<std::uint16_t, std::uint64_t> last;
  std::map<std::uint16_t, std::vector<json>> by;
  for (const auto& msg : m.messages) {
    EXPECT_GE(msg.log_time_ns, last[msg.channel_id]) << "channel " << msg.channel_id;
    last[msg.channel_id] = msg.log_time_ns;
    by[msg.channel_id].push_back(json::parse(msg.data));
  }
  const auto& tel = by[ids["/platform/telemetry"]];
  ASSERT_EQ(tel.size(), 1500u);
  // The time base: wall clock at start minus loop time at start; 1 ms apart as the loop's.
  std::vector<std::uint64_t> tel_ns;
  for (const auto& msg : m.messages)
    if (msg.channel_id == ids["/platform/telemetry"]) tel_ns.push_back(msg.log_time_ns);
  EXPECT_GE(tel_ns.front(), before);
  EXPECT_LE(tel_ns.front(), after);
  EXPECT_NEAR(static_cast<double>(tel_ns.back() - tel_ns.front()), 1.499e9, 1e3);
  const auto& events = by[ids["/events"]];
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0]["kind"], "take_control");
  EXPECT_EQ(events[0]["client"], 3);
  EXPECT_EQ(events[1]["level"], 2);
  EXPECT_EQ(events[1]["t_s"], 100.1);  // the loop time as stamped; the log time does not go back
  const auto& commands = by[ids["/console/command"]];
  ASSERT_EQ(commands.size(), 1u);
  EXPECT_EQ(commands[0]["message"], "{not json");  // kept as text
  EXPECT_EQ(by[ids["/console/action"]][0]["message"]["action"], "take_control");
  ASSERT_NE(m.find_metadata("microcobot"), nullptr);
  EXPECT_EQ(*m.find_metadata("microcobot")->find("version"), "microcobot 9.9.9");
  EXPECT_EQ(*m.find_metadata("scene")->find("kind"), "pick-place");
  EXPECT_EQ(*m.find_metadata("configuration")->find("yaml"), "loop:\n  base_rate_Hz: 10000\n");
  ASSERT_EQ(m.attachments.size(), 1u);
  EXPECT_EQ(m.attachments[0].name, "configuration.yaml");
}

TEST(SessionRecording, HoldsTheRobotsFramesAHundredTimesASecondAndItsBodiesWhenTheyChange) {
  test::TempDir dir;
  auto p = params(dir.path(), false);
  p.telemetry = platform::builtin_telemetry(true);  // the stage's channels: the frames are drawn
  const platform::TelemetrySchema& schema = p.telemetry;
  const std::size_t x = schema.index("measured_x_m"), theta = schema.index("measured_theta_rad");
  SessionRecording rec(p);
  const std::string name = rec.start(5.0, "{}");
  RobotBodies bodies{40e-6, 20e-6, 10e-6, 100e-6};
  rec.robot_bodies(5.0, bodies);
  for (int i = 0; i < 500; ++i) {
    platform::TelemetrySample s{};
    s[0] = 5.0 + 0.001 * i;
    s[x] = 1e-6 * i;
    s[theta] = 0.01 * i;
    if (i == 200) continue;  // a lost sample: the next one carries the frames
    rec.telemetry(s, schema.size());
    if (i % 100 == 50) rec.robot_bodies(s[0], bodies);  // unchanged: not written again
    if (i == 300) {
      bodies.part_side_m = 50e-6;  // another scene
      rec.robot_bodies(s[0], bodies);
    }
  }
  rec.stop();

  const McapContents m = read_mcap(dir / name);
  std::map<std::string, std::uint16_t> ids;
  for (const auto& c : m.channels) ids[c.topic] = c.id;
  ASSERT_EQ(ids.count("/tf"), 1u);
  ASSERT_EQ(ids.count("/robot/scene"), 1u);
  std::map<std::uint64_t, json> telemetry;  // by log time
  std::vector<std::pair<std::uint64_t, json>> tf, scenes;
  for (const auto& msg : m.messages) {
    if (msg.channel_id == ids["/platform/telemetry"]) telemetry[msg.log_time_ns] = json::parse(msg.data);
    if (msg.channel_id == ids["/tf"]) tf.emplace_back(msg.log_time_ns, json::parse(msg.data));
    if (msg.channel_id == ids["/robot/scene"]) scenes.emplace_back(msg.log_time_ns, json::parse(msg.data));
  }
  ASSERT_EQ(telemetry.size(), 499u);
  // 5.000, 5.010, ..., 5.490, with 5.201 for the lost 5.200.
  ASSERT_EQ(tf.size(), 50u);
  for (const auto& [ns, frames] : tf) {
    ASSERT_EQ(telemetry.count(ns), 1u) << "a /tf without the telemetry sample of its log time";
    const json& s = telemetry[ns];
    const json& tool = frames["transforms"][0];
    EXPECT_EQ(tool["child_frame_id"], "tool");
    // The telemetry's JSON keeps 10 significant digits, the frames every one.
    const double measured = s["measured_x_m"];
    EXPECT_NEAR(tool["translation"]["x"].get<double>(), measured, 1e-9 * std::abs(measured));
    EXPECT_NEAR(frames["transforms"][1]["rotation"]["z"].get<double>(),
                std::sin(0.5 * s["measured_theta_rad"].get<double>()), 1e-15);
  }
  EXPECT_EQ(telemetry[tf[20].first]["t_s"], 5.201);  // after 5.000 ... 5.190
  ASSERT_EQ(scenes.size(), 2u);                      // the start and the part's new side
  for (const auto& [ns, scene] : scenes) EXPECT_EQ(scene["entities"].size(), 3u);
  EXPECT_EQ(scenes[1].second["entities"][2]["cubes"][0]["size"]["x"], 50e-6);
}

TEST(SessionRecording, ATelemetryWithoutTheStagesChannelsRecordsNoFrames) {
  test::TempDir dir;
  SessionRecording rec(params(dir.path(), false));
  const std::string name = rec.start(0.0, "{}");
  rec.robot_bodies(0.0, RobotBodies{40e-6, 20e-6, 10e-6, 100e-6});
  for (int i = 0; i < 100; ++i) rec.telemetry(sample(0.001 * i), kChannels);
  rec.stop();
  const McapContents m = read_mcap(dir / name);
  for (const auto& c : m.channels) EXPECT_TRUE(c.topic != "/tf" && c.topic != "/robot/scene") << c.topic;
  EXPECT_EQ(m.messages.size(), 100u);
}

TEST(SessionRecording, TheCsvIsWrittenOnlyWhenAsked) {
  test::TempDir dir;
  SessionRecording rec(params(dir.path(), true));
  const std::string name = rec.start(0.0, "{}");
  for (int i = 0; i < 300; ++i) rec.telemetry(sample(0.001 * i), kChannels);
  rec.stop();
  const std::string csv = name.substr(0, name.size() - 5) + ".csv";
  const CsvTable table = read_csv(dir / csv);
  EXPECT_EQ(table.rows(), 300u);
  EXPECT_EQ(table.names().size(), kChannels);
}

TEST(SessionRecording, AFullDiskEndsTheRecordingReadableUpToItsLastChunkAndIsReported) {
  test::TempDir dir;
  std::atomic<int> errors{0};
  std::string why;
  auto p = params(dir.path(), true);
  p.on_error = [&](const std::string& w) {
    why = w;
    errors.fetch_add(1);
  };
  SessionRecording rec(std::move(p));
  // The disk "full" at 256 KiB per file (a few half-second chunks): writes fail with EFBIG (the signal that
  // would kill the process instead is ignored), even for root, whom permissions would not stop.
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit old{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
  rlimit small = old;
  small.rlim_cur = 256 * 1024;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  rec.start(0.0, "{}");
  // Telemetry until a half-second chunk no longer fits: the writer fails there, cuts the file
  // back to its last whole chunk and closes it; the CSV file is removed.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  for (int i = 0; errors.load() == 0 && std::chrono::steady_clock::now() < deadline; ++i) {
    rec.telemetry(sample(0.001 * i), kChannels);
    if (i % 1000 == 999) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_EQ(errors.load(), 1);
  EXPECT_THAT(why, HasSubstr("disk full"));
  EXPECT_THAT(why, HasSubstr("kept up to its last half second"));
  EXPECT_EQ(rec.name(), "");
  EXPECT_NO_THROW(rec.stop());  // already reported
  std::vector<fs::path> left;
  for (const auto& e : fs::directory_iterator(dir.path())) left.push_back(e.path());
  ASSERT_EQ(left.size(), 1u) << "the MCAP file alone, under its name";
  EXPECT_EQ(left[0].extension(), ".mcap");
  const McapContents kept = read_mcap(left[0]);  // whole, indexed
  const auto telemetry = std::count_if(kept.messages.begin(), kept.messages.end(), [&](const McapMessage& m) {
    return kept.channel(m.channel_id)->topic == "/platform/telemetry";
  });
  EXPECT_GE(telemetry, 500) << "at least one half-second chunk of 1 kHz telemetry";
  EXPECT_EQ(telemetry % 500, 0) << "whole half-second chunks";
  fs::remove(left[0]);
  // No room at all: the files cannot be written when the recording starts or closes; either
  // throws and nothing remains.
  small.rlim_cur = 1;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  bool threw = false;
  try {
    rec.start(0.0, "{}");
    rec.telemetry(sample(0.0), kChannels);
    rec.stop();
  } catch (const Error& e) {
    threw = true;
    EXPECT_THAT(e.what(), HasSubstr(dir.path().string()));
  }
  EXPECT_TRUE(threw);
  setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_TRUE(fs::is_empty(dir.path()));
  // And it records again once the disk has room.
  const std::string name = rec.start(0.0, "{}");
  rec.stop();
  EXPECT_NO_THROW(read_mcap(dir / name));
}

}  // namespace
}  // namespace mc::live
