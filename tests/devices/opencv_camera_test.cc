// The real-camera driver (OpenCV's VideoCapture) on a synthetic source: GStreamer's videotestsrc
// (a moving ball), selected by the configuration like a lab's camera.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <thread>
#include <vector>

#include "microcobot/core/error.h"
#include "microcobot/core/jpeg.h"
#include "microcobot/platform/driver_registry.h"
#include "microcobot/platform/platform.h"

namespace mc::devices {
namespace {

bool have_opencv() {
  const auto names = platform::camera_driver_names();
  return std::find(names.begin(), names.end(), "opencv") != names.end();
}

platform::PlatformConfig opencv_config(const std::string& source) {
  platform::PlatformConfig c;
  c.devices.camera.driver = "opencv";
  c.devices.camera.source = source;
  c.loop.realtime = true;
  return c;
}

constexpr const char* kTestPattern =
    "videotestsrc pattern=ball is-live=true ! video/x-raw,width=320,height=240,framerate=30/1 ! videoconvert "
    "! "
    "appsink";

TEST(OpenCvCamera, GrabsASyntheticSourceStampedWithTheLoopTime) {
  if (!have_opencv()) GTEST_SKIP() << "built without MC_WITH_OPENCV";
  std::unique_ptr<platform::Platform> platform;
  try {
    platform = std::make_unique<platform::Platform>(opencv_config(kTestPattern));
  } catch (const InvalidInput& e) {
    // OpenCV built without its GStreamer back-end cannot open the pipeline (the message lists the
    // back-ends it has).
    GTEST_SKIP() << e.what();
  }
  ASSERT_NE(platform->camera(), nullptr);
  EXPECT_FALSE(platform->camera()->renders_scene());
  std::mutex mutex;
  std::vector<CameraFrame> frames;
  platform->camera()->set_sink([&](const CameraFrame& f) {
    std::lock_guard lock(mutex);
    if (frames.size() < 200) frames.push_back(f);
  });
  platform->loop().run_realtime(15000);  // 1.5 s of loop time at 10 kHz
  platform->camera()->set_sink(nullptr);
  std::lock_guard lock(mutex);
  ASSERT_GE(frames.size(), 15u) << "about 30 frames a second; " << platform->camera()->stats().error;
  double previous = -1.0;
  std::vector<std::uint8_t> first_pixels;
  bool moved = false;
  for (const CameraFrame& f : frames) {
    EXPECT_EQ(f.image.width, 320);
    EXPECT_EQ(f.image.height, 240);
    EXPECT_EQ(f.image.channels, 3) << "colour, as RGB";
    // Stamped on the loop's clock: within the run, increasing, half an exposure before the grab.
    EXPECT_GT(f.t_mid_s, previous);
    EXPECT_LT(f.t_mid_s, 1.6);
    previous = f.t_mid_s;
    const JpegImage jpeg = decode_jpeg(f.jpeg, 3);
    EXPECT_EQ(jpeg.width, 320);
    EXPECT_EQ(jpeg.height, 240);
    if (first_pixels.empty()) first_pixels = f.image.data;
    moved = moved || f.image.data != first_pixels;
  }
  EXPECT_TRUE(moved) << "the ball moves: frames are grabbed, not repeated";
  const CameraStats s = platform->camera()->stats();
  EXPECT_TRUE(s.error.empty()) << s.error;
}

TEST(OpenCvCamera, ASourceThatCannotBeOpenedIsNamedAndNothingIsBuilt) {
  if (!have_opencv()) GTEST_SKIP() << "built without MC_WITH_OPENCV";
  try {
    platform::Platform p(opencv_config("/nonexistent/camera-42.avi"));
    FAIL() << "built";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/camera-42.avi"), std::string::npos) << e.what();
  }
  platform::PlatformConfig empty = opencv_config("");
  EXPECT_THROW(platform::Platform p(empty), InvalidParams);
}

}  // namespace
}  // namespace mc::devices
