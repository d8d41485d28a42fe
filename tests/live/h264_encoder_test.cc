// The recordings' H.264 encoder (live/h264_encoder.h) on the simulated microscope's own frames:
// its packets read by the H.264 syntax (ITU-T H.264 7.3: the NAL unit header, the slice header's
// first two fields), decoded by a decoder that shares none of our code (Debian's `ffmpeg`
// program) and compared with the lossless frames (PSNR = 10 log10(255^2 / MSE)).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/core/jpeg.h"
#include "microcobot/imaging/renderer.h"
#include "microcobot/live/h264_encoder.h"
#include "microcobot/platform/camera_scene.h"
#include "support/test_support.h"

namespace mc::live {
namespace {

// The NAL units of an Annex B byte stream (ITU-T H.264 B.1: each after 00 00 01, a zero byte
// before it belonging to the start code).
std::vector<std::span<const std::uint8_t>> nal_units_of(std::span<const std::uint8_t> b) {
  std::vector<std::size_t> starts;
  for (std::size_t i = 0; i + 3 <= b.size(); ++i)
    if (b[i] == 0 && b[i + 1] == 0 && b[i + 2] == 1) starts.push_back(i + 3);
  std::vector<std::span<const std::uint8_t>> units;
  for (std::size_t k = 0; k < starts.size(); ++k) {
    std::size_t end = k + 1 < starts.size() ? starts[k + 1] - 3 : b.size();
    while (end > starts[k] && b[end - 1] == 0) --end;  // trailing zeros belong to the next start code
    units.push_back(b.subspan(starts[k], end - starts[k]));
  }
  return units;
}

// Exp-Golomb ue(v) of an RBSP (H.264 9.1), emulation prevention bytes (00 00 03) skipped.
struct RbspBits {
  std::span<const std::uint8_t> nal;
  std::size_t byte = 1, bit = 0;  // after the one-byte NAL header
  int zeros = 0;
  int next() {
    if (byte >= nal.size()) return 0;
    if (bit == 0 && zeros >= 2 && nal[byte] == 3) {  // emulation prevention: skipped
      ++byte;
      zeros = 0;
    }
    const int v = (nal[byte] >> (7 - bit)) & 1;
    if (++bit == 8) {
      zeros = nal[byte] == 0 ? zeros + 1 : 0;
      bit = 0;
      ++byte;
    }
    return v;
  }
  unsigned ue() {
    int leading = 0;
    while (next() == 0 && leading < 32) ++leading;
    unsigned v = 0;
    for (int i = 0; i < leading; ++i) v = (v << 1) | static_cast<unsigned>(next());
    return (1u << leading) - 1u + v;
  }
};

// What one packet holds: NAL unit types 5 (IDR slice), 1 (non-IDR slice), 7 (SPS), 8 (PPS).
struct PacketSyntax {
  int idr_slices = 0, slices = 0, sps = 0, pps = 0;
  int pictures = 0;  // slices starting a picture (first_mb_in_slice 0)
  int b_slices = 0;  // slice_type 1 or 6
};

PacketSyntax syntax_of(std::span<const std::uint8_t> packet) {
  PacketSyntax s;
  for (const auto nal : nal_units_of(packet)) {
    if (nal.empty()) continue;
    const int type = nal[0] & 0x1F;
    if (type == 7) ++s.sps;
    if (type == 8) ++s.pps;
    if (type != 1 && type != 5) continue;
    ++s.slices;
    if (type == 5) ++s.idr_slices;
    RbspBits bits{nal};
    if (bits.ue() == 0) ++s.pictures;      // first_mb_in_slice
    if (bits.ue() % 5 == 1) ++s.b_slices;  // slice_type: 0 P, 1 B, 2 I, 3 SP, 4 SI (+5: all alike)
  }
  return s;
}

// The pick-and-place at the platform's camera (1280 x 1024, 12 bits, the power-up objective):
// the gripper circling 150 um around the stage's home, opening and closing, focused on it.
struct MicroscopeClip {
  platform::PlatformConfig config;
  std::unique_ptr<imaging::Renderer> renderer;
  imaging::CameraControls controls;
  imaging::SceneSnapshot snapshot;
  imaging::Frame rendered;
  platform::CameraScenePose pose;

  MicroscopeClip() {
    auto& cam = config.camera;
    cam.view_center_x_m = config.stage.home_x_m;
    cam.view_center_y_m = config.stage.home_y_m;
    renderer = std::make_unique<imaging::Renderer>(platform::renderer_params(cam, cam.objective));
    pose = platform::initial_pose(config);
    controls = renderer->default_controls();
  }
  double rate_Hz() const { return config.camera.frame_rate_Hz(); }
  devices::Image frame(int k) {
    const double t = k / rate_Hz(), w = 2.0 * std::numbers::pi * 0.25;  // a turn in 4 s
    pose.tool_x_m = config.stage.home_x_m + 150e-6 * std::cos(w * t);
    pose.tool_y_m = config.stage.home_y_m + 150e-6 * std::sin(w * t);
    pose.vx_m_s = -150e-6 * w * std::sin(w * t);
    pose.vy_m_s = 150e-6 * w * std::cos(w * t);
    pose.opening_m = config.world.part_side_m * (1.2 + 0.4 * std::sin(3.0 * t));
    controls.focus_z_m = pose.tool_z_m;
    platform::fill_camera_scene(config, pose, snapshot);
    renderer->render(snapshot, controls, 7, static_cast<std::uint64_t>(k), rendered);
    devices::Image image;
    image.resize(rendered.width, rendered.height, 1, rendered.bit_depth);
    for (std::size_t i = 0; i < rendered.pixels.size(); ++i) {
      image.data[2 * i] = static_cast<std::uint8_t>(rendered.pixels[i] & 0xFF);
      image.data[2 * i + 1] = static_cast<std::uint8_t>(rendered.pixels[i] >> 8);
    }
    return image;
  }
};

// Runs `command` (sh); its exit status.
int run_shell(const std::string& command) {
  const int rc = std::system(command.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

TEST(H264Encoder, TheMicroscopesFramesDecodeElsewhereAbove38dBAtATenthOfTheJpegBytes) {
  if (run_shell("ffmpeg -version >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "no ffmpeg (scripts/install-deps.sh test)";
  test::TempDir dir;
  MicroscopeClip clip;
  H264Encoder encoder(H264Params{}, clip.rate_Hz());
  constexpr int kFrames = 80;  // 2.7 s: two keyframes
  std::ofstream stream(dir.path() / "clip.h264", std::ios::binary),
      reference(dir.path() / "clip.y", std::ios::binary);
  JpegEncoder jpeg;
  std::vector<std::uint8_t> jpeg_bytes;
  std::size_t jpeg_total = 0, h264_total = 0;
  std::vector<double> keyframes_s;
  std::vector<double> encode_ms;
  int packets = 0, width = 0, height = 0;
  std::string samples;
  for (int k = 0; k < kFrames; ++k) {
    const devices::Image image = clip.frame(k);
    const VideoImage v = to_video_image(image, samples);
    width = v.width, height = v.height;
    reference.write(samples.data(), static_cast<std::streamsize>(samples.size()));
    jpeg.encode({image.width, image.height, 1, image.bit_depth, image.data}, clip.config.camera.jpeg_quality,
                jpeg_bytes);
    jpeg_total += jpeg_bytes.size();
    const auto t0 = std::chrono::steady_clock::now();
    encoder.encode(v, k / clip.rate_Hz(), static_cast<std::uint64_t>(k), [&](const H264Packet& p) {
      EXPECT_EQ(p.tag, static_cast<std::uint64_t>(packets)) << "packets leave in the frames' order";
      const PacketSyntax s = syntax_of(p.annexb);
      EXPECT_EQ(s.pictures, 1) << "packet " << packets << ": one picture";
      EXPECT_EQ(s.b_slices, 0) << "packet " << packets << ": no B slice";
      EXPECT_EQ(p.keyframe, s.idr_slices > 0) << "packet " << packets;
      if (p.keyframe) {
        EXPECT_EQ(s.idr_slices, s.slices) << "packet " << packets << ": an IDR picture";
        EXPECT_GE(s.sps, 1) << "packet " << packets << ": a keyframe carries its SPS";
        EXPECT_GE(s.pps, 1) << "packet " << packets << ": and its PPS";
        keyframes_s.push_back(p.t_s);
      }
      stream.write(reinterpret_cast<const char*>(p.annexb.data()),
                   static_cast<std::streamsize>(p.annexb.size()));
      h264_total += p.annexb.size();
      ++packets;
    });
    encode_ms.push_back(1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  encoder.flush([&](const H264Packet& p) {
    stream.write(reinterpret_cast<const char*>(p.annexb.data()),
                 static_cast<std::streamsize>(p.annexb.size()));
    h264_total += p.annexb.size();
    ++packets;
  });
  stream.close();
  reference.close();
  EXPECT_EQ(packets, kFrames);
  ASSERT_GE(keyframes_s.size(), 2u);
  EXPECT_EQ(keyframes_s.front(), 0.0);
  for (std::size_t i = 1; i < keyframes_s.size(); ++i)
    EXPECT_LE(keyframes_s[i] - keyframes_s[i - 1], 2.0 + 1e-9) << "keyframe " << i;
  EXPECT_LE(kFrames / clip.rate_Hz() - keyframes_s.back(), 2.0);

  // The independent decoder: its pictures in full-range 4:2:0, as they came out.
  ASSERT_EQ(
      run_shell(fmt::format("ffmpeg -v error -nostdin -f h264 -i '{}' -fps_mode passthrough -f rawvideo "
                            "-pix_fmt yuvj420p '{}'",
                            (dir.path() / "clip.h264").string(), (dir.path() / "clip.yuv").string())),
      0);
  std::ifstream decoded(dir.path() / "clip.yuv", std::ios::binary),
      lossless(dir.path() / "clip.y", std::ios::binary);
  const std::size_t luma = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  std::vector<char> y(luma), chroma(luma / 2), ref(luma);
  double squared_total = 0.0, worst_psnr = 1e9, chroma_offset = 0.0;
  int frames = 0;
  while (decoded.read(y.data(), static_cast<std::streamsize>(luma)) &&
         decoded.read(chroma.data(), static_cast<std::streamsize>(luma / 2))) {
    ASSERT_TRUE(lossless.read(ref.data(), static_cast<std::streamsize>(luma))) << "more pictures than frames";
    double sq = 0.0;
    for (std::size_t i = 0; i < luma; ++i) {
      const double d =
          static_cast<double>(static_cast<std::uint8_t>(y[i])) - static_cast<std::uint8_t>(ref[i]);
      sq += d * d;
    }
    for (char c : chroma)
      chroma_offset = std::max(chroma_offset, std::abs(static_cast<std::uint8_t>(c) - 128.0));
    squared_total += sq;
    worst_psnr = std::min(worst_psnr,
                          10.0 * std::log10(255.0 * 255.0 * static_cast<double>(luma) / std::max(sq, 1e-9)));
    ++frames;
  }
  EXPECT_EQ(frames, kFrames) << "every packet decodes to one picture";
  const double psnr = 10.0 * std::log10(255.0 * 255.0 * static_cast<double>(luma) * frames / squared_total);
  std::sort(encode_ms.begin(), encode_ms.end());
  const double ratio = static_cast<double>(h264_total) / static_cast<double>(jpeg_total);
  std::printf(
      "%dx%d, %d frames: PSNR %.2f dB (worst frame %.2f dB); H.264 %.1f kB a frame, JPEG (quality %d) "
      "%.1f kB: ratio %.4f; encode p50 %.1f ms, max %.1f ms\n",
      width, height, frames, psnr, worst_psnr, 1e-3 * h264_total / kFrames, clip.config.camera.jpeg_quality,
      1e-3 * jpeg_total / kFrames, ratio, encode_ms[encode_ms.size() / 2], encode_ms.back());
  EXPECT_GE(psnr, 38.0);
  EXPECT_GE(worst_psnr, 38.0);
  EXPECT_LE(ratio, 0.1);
  EXPECT_EQ(chroma_offset, 0.0) << "grey frames stay grey (chroma 128)";
}

// A pattern moving right, 2 px a frame: frame k of a 160 x 128 grey clip.
std::vector<std::uint8_t> moving_pattern(int k, int width = 160, int height = 128) {
  std::vector<std::uint8_t> p(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      p[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)] =
          static_cast<std::uint8_t>(128 + 100 * std::sin(0.1 * (x - 2 * k)) * std::cos(0.07 * y));
  return p;
}

TEST(H264Encoder, AKeyframeComesEveryTwoSecondsOfFrameTimeWhateverFramesTheCameraSkipped) {
  // A 30 fps camera that delivers every third frame: 60 frames (the encoder's GOP at 30 fps) span
  // 6 s; the keyframes still come by the frames' time.
  H264Encoder encoder(H264Params{}, 30.0);
  std::vector<double> keys;
  std::uint64_t out = 0;
  const auto sink = [&](const H264Packet& p) {
    if (p.keyframe) keys.push_back(p.t_s);
    ++out;
  };
  for (int k = 0; k < 90; ++k) {
    const auto p = moving_pattern(k);
    encoder.encode({160, 128, 1, p}, 3.0 * k / 30.0, 0, sink);
  }
  encoder.flush(sink);
  EXPECT_EQ(out, 90u);
  ASSERT_GE(keys.size(), 4u);  // 9 s of frames
  for (std::size_t i = 1; i < keys.size(); ++i)
    EXPECT_LE(keys[i] - keys[i - 1], 2.0 + 1e-9) << "keyframe " << i;
}

TEST(H264Encoder, AFrameOfAnotherSizeStartsANewStreamAtAKeyframe) {
  H264Encoder encoder(H264Params{}, 30.0);
  std::vector<bool> keys;
  const auto sink = [&](const H264Packet& p) { keys.push_back(p.keyframe); };
  for (int k = 0; k < 5; ++k) {
    const auto p = moving_pattern(k);
    encoder.encode({160, 128, 1, p}, k / 30.0, 0, sink);
  }
  const auto other = moving_pattern(5, 96, 64);
  encoder.encode({96, 64, 1, other}, 5 / 30.0, 0, sink);
  encoder.flush(sink);
  ASSERT_EQ(keys.size(), 6u);
  EXPECT_TRUE(keys[0]);
  EXPECT_FALSE(keys[1]);
  EXPECT_TRUE(keys[5]) << "the new size's first picture is an IDR";
}

TEST(H264Encoder, DeeperSamplesGiveTheirTopEightBitsAndBadInputIsRefusedNamingIt) {
  devices::Image twelve;
  twelve.resize(2, 1, 1, 12);
  twelve.data = {0xFF, 0x0F, 0x10, 0x00};  // 4095, 16
  std::string out;
  const VideoImage v = to_video_image(twelve, out);
  ASSERT_EQ(v.data.size(), 2u);
  EXPECT_EQ(v.data[0], 255);
  EXPECT_EQ(v.data[1], 1);

  H264Params bad;
  bad.preset = "fastest";
  try {
    H264Encoder e(bad, 30.0);
    FAIL() << "a preset x264 does not have was accepted";
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("preset"), std::string::npos) << e.what();
  }
  H264Encoder encoder(H264Params{}, 30.0);
  const std::vector<std::uint8_t> short_frame(100);
  EXPECT_THROW(encoder.encode({160, 128, 1, short_frame}, 0.0, 0, [](const H264Packet&) {}), InvalidInput);
}

}  // namespace
}  // namespace mc::live
