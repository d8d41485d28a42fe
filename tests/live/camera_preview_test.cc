// The console's preview of the camera (live/camera_preview.h): the frame binned to the panel,
// f x f means, deeper samples cut to their top 8 bits, as a JPEG of that size.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "microcobot/core/error.h"
#include "microcobot/core/jpeg.h"
#include "microcobot/live/camera_preview.h"

namespace mc::live {
namespace {

// A smooth pattern (JPEG keeps it within a few DN) with its 8-bit value at each pixel.
int pattern(int x, int y) { return 40 + (x * 150) / 1300 + (y * 50) / 1100; }

TEST(CameraPreview, TheBinningBringsAnyWidthToThePanel) {
  EXPECT_EQ(CameraPreview::binning(640), 1);
  EXPECT_EQ(CameraPreview::binning(320), 1);
  EXPECT_EQ(CameraPreview::binning(641), 2);
  EXPECT_EQ(CameraPreview::binning(1280), 2);
  EXPECT_EQ(CameraPreview::binning(2048), 4);
  EXPECT_THROW(CameraPreview::binning(0), InvalidInput);
  EXPECT_THROW(CameraPreview::binning(1280, -1), InvalidInput);
}

TEST(CameraPreview, ATwelveBitFrameBecomesTheMeansOfItsBlocksAtEightBits) {
  devices::Image full;
  full.resize(1279, 1025, 1, 12);  // remainders that fill no block are left out
  for (int y = 0; y < full.height; ++y)
    for (int x = 0; x < full.width; ++x) {
      // 12-bit samples whose top 8 bits are the pattern, the low 4 bits varying in the block.
      const unsigned v = static_cast<unsigned>(pattern(x, y)) * 16u + static_cast<unsigned>((x + y) % 16);
      const std::size_t at = 2 * (static_cast<std::size_t>(y) * 1279 + static_cast<std::size_t>(x));
      full.data[at] = static_cast<std::uint8_t>(v & 0xFF);
      full.data[at + 1] = static_cast<std::uint8_t>(v >> 8);
    }
  CameraPreview preview;
  const std::vector<std::uint8_t>& jpeg = preview.encode(full, 95);
  ASSERT_EQ(preview.width(), 639);
  ASSERT_EQ(preview.height(), 512);
  // The binned image: each value the rounded mean of its 2 x 2 block, then >> 4.
  for (int y : {0, 100, 511})
    for (int x : {0, 333, 638}) {
      unsigned sum = 0;
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
          const int xx = 2 * x + dx, yy = 2 * y + dy;
          sum += static_cast<unsigned>(pattern(xx, yy)) * 16u + static_cast<unsigned>((xx + yy) % 16);
        }
      const unsigned expected = ((sum + 2) / 4) >> 4;
      EXPECT_EQ(preview.binned().data[static_cast<std::size_t>(y) * 639 + static_cast<std::size_t>(x)],
                expected)
          << x << "," << y;
    }
  // The JPEG is that image, by an independent decode.
  const JpegImage back = decode_jpeg(jpeg, 1);
  ASSERT_EQ(back.width, 639);
  ASSERT_EQ(back.height, 512);
  double worst = 0;
  for (std::size_t i = 0; i < back.pixels.size(); ++i)
    worst = std::max(worst, std::abs(double(back.pixels[i]) - double(preview.binned().data[i])));
  EXPECT_LE(worst, 3.0);
}

TEST(CameraPreview, AnImageAlreadyThePanelsSizeIsKeptAsItIs) {
  devices::Image rgb;
  rgb.resize(320, 240, 3, 8);
  for (std::size_t i = 0; i < rgb.data.size(); ++i) rgb.data[i] = static_cast<std::uint8_t>(i % 251);
  CameraPreview preview;
  preview.encode(rgb, 90);
  EXPECT_EQ(preview.width(), 320);
  EXPECT_EQ(preview.height(), 240);
  EXPECT_EQ(preview.binned().data, rgb.data);
}

TEST(CameraPreview, AMalformedImageIsRefusedInOneLine) {
  devices::Image bad;
  bad.resize(64, 64, 1, 8);
  bad.data.resize(10);
  CameraPreview preview;
  try {
    preview.encode(bad, 90);
    FAIL() << "accepted 10 bytes for 64x64";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("10 bytes for a 64x64"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mc::live
