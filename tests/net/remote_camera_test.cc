// The slave's camera as the master's (net/remote_camera.h): frames published on the camera's DDS
// topic (camera_image_publisher.h) come out of the remote source decoded, at the configured
// sensor's depth, their JPEG kept as it came; a frame of another size faults with both sizes named; a source
// nobody reads from lets the publisher rest.

#include "microcobot/net/remote_camera.h"

#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/core/jpeg.h"
#include "microcobot/net/camera_image_publisher.h"
#include "net/net_test_support.h"

namespace mc::net {
namespace {

// A frame whose JPEG is a horizontal ramp (x * 4 DN) of w x h pixels.
devices::CameraFrame ramp_frame(int w, int h) {
  devices::CameraFrame f;
  std::vector<std::uint8_t> px(static_cast<std::size_t>(w * h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) px[static_cast<std::size_t>(y * w + x)] = static_cast<std::uint8_t>(4 * x);
  JpegEncoder enc;
  enc.encode({w, h, 1, 8, px}, 95, f.jpeg);
  return f;
}

devices::CameraDeviceParams sensor(int w, int h, int bits) {
  devices::CameraDeviceParams p;
  p.sensor.width_px = w;
  p.sensor.height_px = h;
  p.sensor.bit_depth = bits;
  return p;
}

// Captures until a frame comes (the publisher publishing meanwhile), or 10 s.
bool capture_one(RemoteCameraSource& source, CameraImagePublisher& publisher,
                 const devices::CameraFrame& frame, devices::Image& out) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (std::chrono::steady_clock::now() < end) {
    publisher.publish(frame, 1.0);
    if (source.capture({}, out)) return true;
  }
  return false;
}

TEST(RemoteCamera, TheSlavesFramesComeOutDecodedAtTheSensorsDepth) {
  const int domain = test::test_domain_id();
  CameraImagePublisher publisher(domain, {});
  RemoteCameraSource source(domain, {});
  source.open(sensor(64, 48, 12));
  EXPECT_FALSE(source.renders_scene());
  devices::Image img;
  const devices::CameraFrame sent = ramp_frame(64, 48);
  ASSERT_TRUE(capture_one(source, publisher, sent, img));
  ASSERT_NE(source.captured_jpeg(), nullptr);
  EXPECT_EQ(*source.captured_jpeg(), sent.jpeg) << "the slave's JPEG goes on as it came";
  ASSERT_EQ(img.width, 64);
  ASSERT_EQ(img.height, 48);
  ASSERT_EQ(img.bit_depth, 12);
  // Column 20 of the ramp: 80 DN in 8 bits, 80 * 16 in 12 (little-endian), within JPEG's error.
  const std::size_t i = 2 * static_cast<std::size_t>(10 * 64 + 20);
  const int v = img.data[i] | (img.data[i + 1] << 8);
  EXPECT_NEAR(v, 80 * 16, 2 * 16);
  source.close();
}

TEST(RemoteCamera, AFrameOfAnotherSizeFaultsNamingBothSizes) {
  const int domain = test::test_domain_id();
  CameraImagePublisher publisher(domain, {});
  RemoteCameraSource source(domain, {});
  source.open(sensor(1280, 1024, 8));
  devices::Image img;
  try {
    capture_one(source, publisher, ramp_frame(64, 48), img);
    FAIL() << "a 64 x 48 frame for a 1280 x 1024 sensor was taken";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("64 x 48"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("1280 x 1024"), std::string::npos) << e.what();
  }
}

TEST(RemoteCamera, ASourceNobodyReadsFromLetsTheSlaveRest) {
  const int domain = test::test_domain_id();
  CameraImagePublisher publisher(domain, {});
  RemoteCameraSource source(domain, {});
  source.open(sensor(64, 48, 8));
  EXPECT_FALSE(publisher.wanted()) << "opened, not yet reading";
  devices::Image img;
  ASSERT_TRUE(capture_one(source, publisher, ramp_frame(64, 48), img));
  EXPECT_TRUE(publisher.wanted());
  source.idle();
  EXPECT_TRUE(test::wait_until([&] { return !publisher.wanted(); }));
  ASSERT_TRUE(capture_one(source, publisher, ramp_frame(64, 48), img));
  EXPECT_TRUE(publisher.wanted());
}

}  // namespace
}  // namespace mc::net
