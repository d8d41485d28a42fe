// The camera's frames through the live server: every frame in the recording as a
// CDR sensor_msgs/msg/CompressedImage (with its CameraInfo and state), none dropped; focus and
// objective commands through the console's command path.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <thread>

#include <nlohmann/json.hpp>

#include "microcobot/core/jpeg.h"
#include "microcobot/core/mcap_reader.h"
#include "microcobot/live/camera_messages.h"
#include "microcobot/live/console_server.h"
#include "support/console_client.h"
#include "support/sanitizers.h"
#include "support/test_camera.h"
#include "support/test_support.h"
#include "support/ws_client.h"

namespace mc::live {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;

// A little-endian CDR reader, written from the CDR rules (not the encoder's code).
struct Cdr {
  std::string_view b;
  std::size_t at = 4;
  void align(std::size_t n) { at += (n - (at - 4) % n) % n; }
  template <class T>
  T get() {
    align(sizeof(T));
    T v{};
    EXPECT_LE(at + sizeof(T), b.size());
    if (at + sizeof(T) <= b.size()) std::memcpy(&v, b.data() + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
  std::string str() {
    const auto n = get<std::uint32_t>();
    std::string s(b.substr(at, n ? n - 1 : 0));
    at += n;
    return s;
  }
};

LiveParams camera_params() {
  test::register_test_camera();
  LiveParams p;
  p.platform.devices.camera.driver = "test-pattern";
  p.platform.camera.sensor.width_px = 320;
  p.platform.camera.sensor.height_px = 256;
  p.platform.camera.sensor.bit_depth = 8;
  p.platform.camera.view_center_x_m = p.platform.world.part_start_m.x();
  p.platform.camera.view_center_y_m = p.platform.world.part_start_m.y();
  // A calibration of the power-up objective: published with every frame's state.
  vision::StageCalibration cal;
  cal.objective = p.platform.camera.objectives.at(static_cast<std::size_t>(p.platform.camera.objective)).name;
  cal.px_per_m = {{1.0e6, 2.0e3}, {-1.0e3, -1.0e6}};
  cal.offset_px = {160.0, 128.0};
  cal.residual_rms_px = 0.03;
  p.platform.camera.calibrations = {cal};
  return p;
}

ConsoleServerParams server_params(const std::filesystem::path& out) {
  ConsoleServerParams p;
  p.server.port = 0;
  p.out_dir = out;
  return p;
}

TEST(CameraStream, TheRecordingHoldsEveryFrameAsCdrCompressedImageWithItsCameraInfo) {
  test::TempDir dir;
  LivePlatform live(camera_params());
  ConsoleServerParams sp = server_params(dir.path());
  sp.record_video = RecordedVideo::kJpeg;  // `serve --record-video jpeg` (H.264: recorded_video_test.cc)
  ConsoleServer server(live, sp);
  server.start();
  // Nobody looks yet: the camera forms no frame. The recording is a viewer: frames flow.
  std::this_thread::sleep_for(500ms);
  EXPECT_EQ(live.status().camera_frames, 0u);
  const std::string name = server.start_recording();
  ASSERT_TRUE(test::eventually([&] { return live.status().camera_frames >= 3; }, 10s));
  const std::uint64_t at_start = live.status().camera_frames;
  constexpr std::uint64_t kFrames = 90;  // 3 s at 30 fps
  ASSERT_TRUE(test::eventually([&] { return live.status().camera_frames >= at_start + kFrames; }, 30s));
  server.stop_recording();
  const LiveStatus s = live.status();
  server.stop();

  const McapContents mcap = read_mcap(dir.path() / name);
  std::map<std::string, std::uint16_t> ids;
  for (const McapChannel& c : mcap.channels) ids[c.topic] = c.id;
  ASSERT_TRUE(ids.count("/camera/image/compressed"));
  const McapChannel& image_channel = *mcap.channel(ids["/camera/image/compressed"]);
  EXPECT_EQ(image_channel.message_encoding, "cdr");
  EXPECT_EQ(mcap.schema(image_channel.schema_id)->name, "sensor_msgs/msg/CompressedImage");
  EXPECT_EQ(mcap.schema(image_channel.schema_id)->encoding, "ros2msg");
  std::vector<const McapMessage*> images, infos, states;
  for (const McapMessage& m : mcap.messages) {
    if (m.channel_id == ids["/camera/image/compressed"]) images.push_back(&m);
    if (m.channel_id == ids["/camera/camera_info"]) infos.push_back(&m);
    if (m.channel_id == ids["/camera/state"]) states.push_back(&m);
  }
  // Every frame between start and stop, in sequence, none missing.
  ASSERT_GE(images.size(), kFrames);
  EXPECT_EQ(infos.size(), images.size());
  ASSERT_EQ(states.size(), images.size());
  const auto first = json::parse(states.front()->data)["sequence"].get<std::uint64_t>();
  const json calibration = json::parse(states.front()->data)["calibration"];
  EXPECT_EQ(calibration["px_per_m"], json::parse("[[1.0e6, 2.0e3], [-1.0e3, -1.0e6]]"));
  EXPECT_EQ(calibration["offset_px"], json::parse("[160.0, 128.0]"));
  for (std::size_t k = 0; k < states.size(); ++k) {
    const json st = json::parse(states[k]->data);
    EXPECT_EQ(st["sequence"].get<std::uint64_t>(), first + k) << "frame " << k << " missing";
  }
  // Frames on the camera's 30 fps grid of loop time. A loop far behind the wall clock (the
  // sanitizers on a loaded machine: seen once in CI's asan stage, a 0.1 s gap with no frame counted
  // as dropped) may skip a due frame; the ones it formed stay on the grid, and skips stay rare.
  std::size_t skipped = 0;
  for (std::size_t k = 1; k < images.size(); ++k) {
    const double gap_s = 1e-9 * static_cast<double>(images[k]->log_time_ns - images[k - 1]->log_time_ns);
    const double periods = std::round(gap_s * 30.0);
    EXPECT_GE(periods, 1.0) << "frame " << k;
    EXPECT_NEAR(gap_s, periods / 30.0, 1.5e-3) << "frame " << k << ": on the camera's grid in loop time";
    if (periods > 1.0) ++skipped;
  }
  // Under the sanitizers each frame's rendering and JPEG take several times longer: an asan run
  // beside the cell's tests skipped 5 of 80 due frames; another had 4 frames dropped, due while
  // the camera thread was still busy (a dropped frame is never formed: the sequence above has no
  // gap for it). Both are the camera keeping up, which stays the rule, not the recording's loss.
#if MC_UNDER_SANITIZER
  constexpr std::size_t kSkipShare = 5;
#else
  constexpr std::size_t kSkipShare = 20;
#endif
  EXPECT_LE(skipped + s.camera_dropped, images.size() / kSkipShare)
      << "frames at the camera's rate in loop time (" << skipped << " skipped, " << s.camera_dropped
      << " dropped)";
  // Chunks larger than a frame: several frames in each.
  EXPECT_LT(mcap.chunk_count, images.size() / 2);

  // The CDR decodes by the rules, its JPEG to the sensor's size, its stamp the loop time.
  Cdr cdr{images.back()->data};
  EXPECT_EQ(std::string(cdr.b.substr(0, 4)), std::string("\x00\x01\x00\x00", 4));
  const auto sec = cdr.get<std::int32_t>();
  const auto nanosec = cdr.get<std::uint32_t>();
  EXPECT_EQ(cdr.str(), "camera_optical_frame");
  EXPECT_EQ(cdr.str(), "jpeg");
  const auto n = cdr.get<std::uint32_t>();
  ASSERT_EQ(cdr.at + n, cdr.b.size());
  const JpegImage jpeg =
      decode_jpeg(std::span(reinterpret_cast<const std::uint8_t*>(cdr.b.data() + cdr.at), n));
  EXPECT_EQ(jpeg.width, 320);
  EXPECT_EQ(jpeg.height, 256);
  EXPECT_NEAR(sec + 1e-9 * nanosec, json::parse(states.back()->data)["t_s"].get<double>(), 1e-8);

  // CameraInfo: K from the objective's scale at its working distance.
  Cdr info{infos.back()->data};
  info.get<std::int32_t>(), info.get<std::uint32_t>(), info.str();
  EXPECT_EQ(info.get<std::uint32_t>(), 256u);
  EXPECT_EQ(info.get<std::uint32_t>(), 320u);
  EXPECT_EQ(info.str(), "plumb_bob");
  const auto nd = info.get<std::uint32_t>();
  for (std::uint32_t i = 0; i < nd; ++i) EXPECT_EQ(info.get<double>(), 0.0);
  const double fx = info.get<double>();
  const auto objective = LiveParams().platform.camera.objectives.front();  // the power-up turret (a copy)
  EXPECT_NEAR(fx, objective.working_distance_m / (5.3e-6 / objective.magnification), 1e-6 * fx);
}

TEST(CameraStream, TheCameraFormsFramesOnlyWhileAClientSubscribesToThem) {
  test::TempDir dir;
  LivePlatform live(camera_params());
  ConsoleServer server(live, server_params(dir.path()));
  server.start();
  test::Console console(server.port());
  console.subscribe("/platform/status", 1);  // watching the status is not watching the camera
  std::this_thread::sleep_for(500ms);
  EXPECT_EQ(live.status().camera_frames, 0u);
  console.subscribe("/camera/image/compressed", 2);
  EXPECT_FALSE(console.next_on(2).empty()) << "a subscriber gets frames";
  EXPECT_GT(live.status().camera_frames, 0u);
  ASSERT_TRUE(console.ws.send_json({{"op", "unsubscribe"}, {"subscriptionIds", {2}}}));
  std::this_thread::sleep_for(500ms);  // the demand is read at the status rate (5 Hz)
  const std::uint64_t after = live.status().camera_frames;
  std::this_thread::sleep_for(500ms);
  EXPECT_EQ(live.status().camera_frames, after) << "nobody looks again: the camera stops";
  server.stop();
}

// The JPEG costs the camera thread most of its frame time: it is made only while the image channel,
// a JPEG recording or the DDS image topic needs it; the state (and the preview, the vision, the
// snapshot, an H.264 recording) read the frame raw.
TEST(CameraStream, AFrameCarriesItsJpegOnlyWhileTheImageChannelNeedsIt) {
  test::TempDir dir;
  LivePlatform live(camera_params());
  ConsoleServer server(live, server_params(dir.path()));
  server.start();
  test::Console console(server.port());
  const auto jpeg_bytes = [&](std::uint32_t id) {
    const std::string m = console.next_on(id);
    return m.empty() ? -1 : json::parse(m)["jpeg_bytes"].get<int>();
  };
  console.subscribe("/camera/state", 1);
  for (int k = 0; k < 10; ++k) EXPECT_EQ(jpeg_bytes(1), 0) << "state " << k << ": nobody needs the JPEG";
  console.subscribe("/camera/image/compressed", 2);
  // The demand is read at the status rate (5 Hz): within a second every frame carries its JPEG.
  ASSERT_TRUE(test::eventually([&] { return jpeg_bytes(1) > 0; }, 5s));
  for (int k = 0; k < 5; ++k) EXPECT_GT(jpeg_bytes(1), 1000) << "state " << k;
  ASSERT_TRUE(console.ws.send_json({{"op", "unsubscribe"}, {"subscriptionIds", {2}}}));
  ASSERT_TRUE(test::eventually([&] { return jpeg_bytes(1) == 0; }, 5s));
  for (int k = 0; k < 5; ++k)
    EXPECT_EQ(jpeg_bytes(1), 0) << "state " << k << " after the image's client left";
  server.stop();
}

// The console's panel subscribes to the preview: the same frame (same stamp) binned to 640 px.
TEST(CameraStream, ThePreviewIsTheSameFrameBinnedToTheConsolesPanel) {
  test::TempDir dir;
  LiveParams params = camera_params();
  params.platform.camera.sensor.width_px = 1280;
  params.platform.camera.sensor.height_px = 512;
  LivePlatform live(params);
  ConsoleServer server(live, server_params(dir.path()));
  server.start();
  test::Console console(server.port());
  ASSERT_EQ(console.channels.count(std::string(kCameraPreviewTopic)), 1u);
  console.subscribe(std::string(kCameraPreviewTopic), 3);
  const std::string preview = console.next_on(3);
  ASSERT_FALSE(preview.empty()) << "the preview alone makes the camera form frames";
  console.subscribe("/camera/image/compressed", 4);
  // Frames of both channels by stamp, until one stamp has both.
  std::map<std::pair<std::int32_t, std::uint32_t>, std::string> previews, fulls;
  const auto stamp_of = [](const std::string& m) {
    Cdr c{m};
    const auto sec = c.get<std::int32_t>();
    return std::make_pair(sec, c.get<std::uint32_t>());
  };
  std::pair<std::int32_t, std::uint32_t> both{-1, 0};
  for (int i = 0; i < 400 && both.first < 0; ++i) {
    const auto m = console.ws.read();
    ASSERT_TRUE(m.has_value());
    if (m->text) continue;
    const auto d = server::decode_message_data(m->data);
    const auto* md = std::get_if<server::MessageData>(&d);
    if (!md || (md->subscription != 3 && md->subscription != 4)) continue;
    const std::string payload(md->payload);
    auto& mine = md->subscription == 3 ? previews : fulls;
    const auto& other = md->subscription == 3 ? fulls : previews;
    mine[stamp_of(payload)] = payload;
    if (other.count(stamp_of(payload))) both = stamp_of(payload);
  }
  ASSERT_GE(both.first, 0) << "no frame seen on both channels";
  const auto jpeg_of = [](const std::string& m) {
    Cdr c{m};
    c.get<std::int32_t>(), c.get<std::uint32_t>(), c.str();
    EXPECT_EQ(c.str(), "jpeg");
    const auto n = c.get<std::uint32_t>();
    return decode_jpeg(
        std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(m.data()) + c.at, n), 1);
  };
  const JpegImage small = jpeg_of(previews[both]), big = jpeg_of(fulls[both]);
  ASSERT_EQ(big.width, 1280);
  ASSERT_EQ(small.width, 640);
  ASSERT_EQ(small.height, 256);
  // Each preview pixel is its 2 x 2 block of the full frame (both through JPEG: a few DN).
  double sum = 0;
  for (int y = 0; y < small.height; ++y)
    for (int x = 0; x < small.width; ++x) {
      double block = 0;
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx)
          block +=
              big.pixels[static_cast<std::size_t>(2 * y + dy) * 1280 + static_cast<std::size_t>(2 * x + dx)];
      sum += std::abs(0.25 * block -
                      small.pixels[static_cast<std::size_t>(y) * 640 + static_cast<std::size_t>(x)]);
    }
  EXPECT_LT(sum / (640.0 * 256.0), 2.0) << "mean |preview - binned frame| in DN";
  server.stop();
}

// A baseline TIFF's first IFD entries by tag (SHORT or LONG values), read from the
// specification (TIFF 6.0 Part 1: header "II*\0", IFD offset, 12-byte entries).
std::map<int, std::uint32_t> tiff_tags(const std::string& b) {
  const auto u16 = [&](std::size_t at) {
    return static_cast<std::uint32_t>(static_cast<unsigned char>(b[at]) |
                                      (static_cast<unsigned char>(b[at + 1]) << 8));
  };
  const auto u32 = [&](std::size_t at) { return u16(at) | (u16(at + 2) << 16); };
  std::map<int, std::uint32_t> tags;
  const std::uint32_t ifd = u32(4);
  for (std::uint32_t i = 0; i < u16(ifd); ++i) {
    const std::size_t e = ifd + 2 + 12 * i;
    tags[static_cast<int>(u16(e))] = u16(e + 2) == 3 ? u16(e + 8) : u32(e + 8);
  }
  return tags;
}

// GET /camera/snapshot.tiff|.png: the latest full frame, lossless, as a download named after
// the objective and the time; before any frame, 503 in one line.
TEST(CameraStream, TheSnapshotIsTheLatestFullFrameLosslessWithItsScaleAndState) {
  test::TempDir dir;
  LivePlatform live(camera_params());
  ConsoleServer server(live, server_params(dir.path()));
  server.start();
  const test::HttpResult none = test::http_request(server.port(), "GET", "/camera/snapshot.tiff");
  EXPECT_EQ(none.status, 503);
  EXPECT_NE(none.body.find("no camera frame yet"), std::string::npos) << none.body;
  test::Console console(server.port());
  console.subscribe(std::string(kCameraPreviewTopic), 3);
  ASSERT_FALSE(console.next_on(3).empty());
  ASSERT_FALSE(console.next_on(3).empty());  // the snapshot is kept as the frame is published

  const test::HttpResult tiff = test::http_request(server.port(), "GET", "/camera/snapshot.tiff");
  ASSERT_EQ(tiff.status, 200) << tiff.body.substr(0, 200);
  EXPECT_EQ(tiff.header("content-type"), "image/tiff");
  const std::string disposition = tiff.header("content-disposition");
  EXPECT_NE(disposition.find("attachment; filename=\"snapshot-"), std::string::npos) << disposition;
  EXPECT_NE(disposition.find(".tiff\""), std::string::npos) << disposition;
  ASSERT_GT(tiff.body.size(), 320u * 256u);
  ASSERT_EQ(tiff.body.substr(0, 4), std::string("II*\0", 4));
  std::map<int, std::uint32_t> tags = tiff_tags(tiff.body);
  EXPECT_EQ(tags[256], 320u);  // ImageWidth
  EXPECT_EQ(tags[257], 256u);  // ImageLength
  EXPECT_EQ(tags[258], 8u);    // BitsPerSample: the 8-bit test sensor's, as it gave them
  EXPECT_EQ(tags.count(282), 1u) << "XResolution: the object-side scale";
  EXPECT_EQ(tags[296], 3u) << "ResolutionUnit: centimetre";
  // The samples as the source drew them: its dark field (16) and its bright square, nothing else
  // (a JPEG would have rung at the square's edges).
  const std::size_t strip = tags[273];
  ASSERT_LE(strip + 320u * 256u, tiff.body.size());
  std::map<int, int> values;
  for (std::size_t i = 0; i < 320u * 256u; ++i) ++values[static_cast<unsigned char>(tiff.body[strip + i])];
  EXPECT_EQ(values.size(), 2u);
  EXPECT_GT(values[16], 0);
  EXPECT_NE(tiff.body.find("\"objective\""), std::string::npos) << "the camera's state as ImageDescription";

  const test::HttpResult png = test::http_request(server.port(), "GET", "/camera/snapshot.png");
  ASSERT_EQ(png.status, 200);
  EXPECT_EQ(png.header("content-type"), "image/png");
  EXPECT_EQ(png.body.substr(1, 3), "PNG");
  EXPECT_EQ(test::http_request(server.port(), "GET", "/camera/snapshot.jpg").status, 404);
  server.stop();
}

TEST(CameraStream, FocusAndObjectiveAreConsoleCommandsThatNeedControlButNotTheDeadman) {
  test::TempDir dir;
  LivePlatform live(camera_params());
  ConsoleServer server(live, server_params(dir.path()));
  server.start();
  test::Console console(server.port());
  EXPECT_EQ(console.channels.count("/camera/image/compressed"), 1u);
  EXPECT_EQ(console.channels.count("/camera/camera_info"), 1u);
  // Without control: refused.
  EXPECT_TRUE(console.command({{"focus_z_m", 200e-6}}));
  EXPECT_FALSE(console.ws.read_status("control").is_null());
  EXPECT_TRUE(console.action("take_control"));
  // Deadman released: the microscope still obeys (it is not the slave).
  const json c = {{"deadman", false}, {"focus_z_m", 150e-6}, {"objective", 2}, {"gain", 2.0}};
  EXPECT_TRUE(test::eventually(
      [&] {
        console.command(c);
        const LiveStatus s = live.status();
        return s.objective == 2 && std::abs(s.focus_z_m - 150e-6) < 1e-9;
      },
      10s));
  // An objective that is not on the turret is refused, naming it.
  EXPECT_TRUE(console.command({{"objective", 9}}));
  const json refusal = console.ws.read_status("/console/command");
  EXPECT_NE(refusal.dump().find("objective"), std::string::npos) << refusal.dump();
  server.stop();
}

}  // namespace
}  // namespace mc::live
