// How a live recording keeps the camera (live/recorded_video.h): H.264 as
// foxglove.CompressedVideo, encoded by the recording's writer, neither on the loop's thread (which
// allocates nothing meanwhile) nor on the camera's; JPEG as the console's channel sends it; or no
// camera channel at all, and then no frame formed for the recording.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <map>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "microcobot/core/mcap_reader.h"
#include "microcobot/live/camera_messages.h"
#include "microcobot/live/console_server.h"
#include "support/counting_allocator.h"
#include "support/test_camera.h"
#include "support/test_support.h"

namespace mc::live {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;

LiveParams video_camera_params() {
  test::register_test_camera();
  LiveParams p;
  p.platform.devices.camera.driver = "test-pattern";
  p.platform.camera.sensor.width_px = 320;
  p.platform.camera.sensor.height_px = 256;
  p.platform.camera.sensor.bit_depth = 8;
  return p;
}

ConsoleServerParams video_server_params(const std::filesystem::path& out) {
  ConsoleServerParams p;
  p.server.port = 0;
  p.out_dir = out;
  return p;
}

// RFC 4648 base64, written from the RFC's alphabet (not the encoder's code).
std::string from_base64(const std::string& text) {
  std::string out;
  unsigned acc = 0;
  int bits = 0;
  for (char c : text) {
    int v = -1;
    if (c >= 'A' && c <= 'Z') v = c - 'A';
    if (c >= 'a' && c <= 'z') v = c - 'a' + 26;
    if (c >= '0' && c <= '9') v = c - '0' + 52;
    if (c == '+') v = 62;
    if (c == '/') v = 63;
    if (v < 0) continue;  // padding
    acc = (acc << 6) | static_cast<unsigned>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<char>((acc >> bits) & 0xFF));
    }
  }
  return out;
}

std::map<std::string, std::vector<const McapMessage*>> messages_by_topic(const McapContents& mcap) {
  std::map<std::uint16_t, std::string> topics;
  for (const McapChannel& c : mcap.channels) topics[c.id] = c.topic;
  std::map<std::string, std::vector<const McapMessage*>> by;
  for (const McapMessage& m : mcap.messages) by[topics[m.channel_id]].push_back(&m);
  return by;
}

TEST(RecordedVideo, TheCameraIsRecordedAsH264OffTheLoopAndTheCameraThreadAndDecodesElsewhere) {
  test::TempDir dir;
  LivePlatform live(video_camera_params());
  ConsoleServer server(live, video_server_params(dir.path()));
  std::atomic<std::thread::id> camera_thread{};
  server.add_frame_consumer(
      {[&](const devices::CameraFrame&, double) { camera_thread = std::this_thread::get_id(); },
       [] { return false; }});
  server.start();
  const std::string name = server.start_recording();  // serve's default: h264
  ASSERT_TRUE(test::eventually([&] { return live.status().camera_frames >= 3; }, 10s));
  ASSERT_NE(live.loop_thread_id(), std::thread::id{});
  const std::uint64_t at_start = live.status().camera_frames;
  std::size_t allocations = 0;
  bool recorded = false;
  {
    test::AllocationGuard guard(live.loop_thread_id());
    recorded = test::eventually([&] { return live.status().camera_frames >= at_start + 75; }, 30s);  // 2.5 s
    allocations = guard.allocations();
  }
  server.stop_recording();
  const SessionRecording::VideoStats stats = server.recording_video_stats();
  server.stop();
  ASSERT_TRUE(recorded);
  EXPECT_EQ(allocations, 0u) << "the loop thread allocated while the recording encoded";
  EXPECT_GE(stats.frames, 75u);
  EXPECT_EQ(stats.packets, stats.frames) << "one access unit a frame, the lookahead flushed at the stop";
  EXPECT_GE(stats.keyframes, 2u);
  EXPECT_LE(stats.longest_keyframe_gap_s, 2.0 + 1e-6);
  EXPECT_NE(stats.thread, std::thread::id{});
  EXPECT_NE(stats.thread, live.loop_thread_id()) << "the encoder ran on the loop's thread";
  EXPECT_NE(stats.thread, camera_thread.load()) << "the encoder ran on the camera's thread";

  const McapContents mcap = read_mcap(dir.path() / name);
  auto by = messages_by_topic(mcap);
  EXPECT_EQ(by.count("/camera/image/compressed"), 0u) << "no JPEG channel beside the video";
  const McapChannel* video = nullptr;
  for (const McapChannel& c : mcap.channels)
    if (c.topic == kCameraVideoTopic) video = &c;
  ASSERT_NE(video, nullptr);
  EXPECT_EQ(video->message_encoding, "json");
  EXPECT_EQ(mcap.schema(video->schema_id)->name, "foxglove.CompressedVideo");
  EXPECT_EQ(mcap.schema(video->schema_id)->encoding, "jsonschema");
  const auto& frames = by[std::string(kCameraVideoTopic)];
  const auto& states = by["/camera/state"];
  ASSERT_EQ(frames.size(), stats.packets);
  ASSERT_EQ(states.size(), frames.size());
  EXPECT_EQ(by["/camera/camera_info"].size(), frames.size());
  const McapMetadata* meta = mcap.find_metadata("video");
  ASSERT_NE(meta, nullptr);
  ASSERT_NE(meta->find("format"), nullptr);
  EXPECT_EQ(*meta->find("format"), "h264");

  std::ofstream stream(dir.path() / "video.h264", std::ios::binary);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const json m = json::parse(frames[k]->data);
    EXPECT_EQ(m["format"], "h264");
    EXPECT_EQ(m["frame_id"], std::string(kCameraFrameId));
    const double stamp = m["timestamp"]["sec"].get<double>() + 1e-9 * m["timestamp"]["nsec"].get<double>();
    EXPECT_NEAR(stamp, json::parse(states[k]->data)["t_s"].get<double>(), 1e-8) << "frame " << k;
    EXPECT_EQ(frames[k]->log_time_ns, states[k]->log_time_ns) << "frame " << k;
    const std::string annexb = from_base64(m["data"].get<std::string>());
    ASSERT_GE(annexb.size(), 4u);
    EXPECT_TRUE(annexb.rfind(std::string("\0\0\1", 3), 0) == 0 ||
                annexb.rfind(std::string("\0\0\0\1", 4), 0) == 0)
        << "frame " << k << ": an Annex B start code first";
    stream << annexb;
  }
  stream.close();
  if (std::system("ffmpeg -version >/dev/null 2>&1") != 0) GTEST_SKIP() << "no ffmpeg to decode it";
  // Debian's ffmpeg decodes the messages in order, each to one 320 x 256 picture.
  const auto raw = dir.path() / "video.yuv";
  ASSERT_EQ(
      std::system(fmt::format("ffmpeg -v error -nostdin -f h264 -i '{}' -fps_mode passthrough -f rawvideo "
                              "-pix_fmt yuvj420p '{}'",
                              (dir.path() / "video.h264").string(), raw.string())
                      .c_str()),
      0);
  EXPECT_EQ(std::filesystem::file_size(raw), frames.size() * 320 * 256 * 3 / 2);
}

TEST(RecordedVideo, JpegKeepsTheConsolesFramesAndOffKeepsNoCameraChannelNorAsksForFrames) {
  test::TempDir dir;
  LivePlatform live(video_camera_params());
  ConsoleServerParams sp = video_server_params(dir.path());
  sp.record_video = RecordedVideo::kOff;  // `serve --record-video off`
  ConsoleServer server(live, sp);
  server.start();
  // Off: the recording is no viewer of the camera; nobody else looks, so no frame is formed.
  const std::string off = server.start_recording();
  std::this_thread::sleep_for(1s);
  EXPECT_EQ(live.status().camera_frames, 0u);
  server.stop_recording();
  // The console's request chooses JPEG for this one.
  const std::string jpeg = server.start_recording(RecordedVideo::kJpeg);
  ASSERT_TRUE(test::eventually([&] { return live.status().camera_frames >= 30; }, 20s));
  server.stop_recording();
  server.stop();

  const McapContents without = read_mcap(dir.path() / off);
  for (const McapChannel& c : without.channels)
    EXPECT_EQ(c.topic.rfind("/camera/", 0), std::string::npos) << c.topic << " recorded with video off";
  ASSERT_NE(without.find_metadata("video"), nullptr);
  EXPECT_EQ(*without.find_metadata("video")->find("format"), "off");

  const McapContents with = read_mcap(dir.path() / jpeg);
  auto by = messages_by_topic(with);
  EXPECT_EQ(by.count(std::string(kCameraVideoTopic)), 0u);
  ASSERT_GE(by["/camera/image/compressed"].size(), 25u);
  EXPECT_EQ(by["/camera/image/compressed"].size(), by["/camera/state"].size());
  EXPECT_EQ(*with.find_metadata("video")->find("format"), "jpeg");
}

}  // namespace
}  // namespace mc::live
