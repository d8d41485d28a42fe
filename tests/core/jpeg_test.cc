#include "microcobot/core/jpeg.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "microcobot/core/error.h"

namespace mc {
namespace {

// A grey gradient with a bright square: what a microscope frame roughly is.
std::vector<std::uint8_t> pattern(int w, int h) {
  std::vector<std::uint8_t> px(static_cast<std::size_t>(w * h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      px[static_cast<std::size_t>(y * w + x)] = (x > w / 4 && x < w / 2 && y > h / 4 && y < h / 2)
                                                    ? 230
                                                    : static_cast<std::uint8_t>(20 + (x * 100) / w);
  return px;
}

TEST(Jpeg, GreyFramesRoundTripWithinTheQuantisationOfTheQuality) {
  const int w = 160, h = 120;
  const auto px = pattern(w, h);
  JpegEncoder enc;
  std::vector<std::uint8_t> jpeg;
  enc.encode({w, h, 1, 8, px}, 90, jpeg);
  ASSERT_GT(jpeg.size(), 100u);
  EXPECT_LT(jpeg.size(), px.size()) << "compressed";
  const JpegImage img = decode_jpeg(jpeg);
  ASSERT_EQ(img.width, w);
  ASSERT_EQ(img.height, h);
  double err = 0.0;
  for (std::size_t i = 0; i < px.size(); ++i) err += std::abs(int(img.pixels[i]) - int(px[i]));
  EXPECT_LT(err / static_cast<double>(px.size()), 2.0) << "mean absolute error in grey levels";
}

TEST(Jpeg, DeepSamplesKeepTheirTopEightBits) {
  const int w = 64, h = 48;
  std::vector<std::uint8_t> px(static_cast<std::size_t>(w * h * 2));
  for (std::size_t i = 0; i < px.size() / 2; ++i) {
    const unsigned v = 2000;  // 12-bit: 2000 >> 4 = 125
    px[2 * i] = static_cast<std::uint8_t>(v & 0xFF);
    px[2 * i + 1] = static_cast<std::uint8_t>(v >> 8);
  }
  JpegEncoder enc;
  std::vector<std::uint8_t> jpeg;
  enc.encode({w, h, 1, 12, px}, 95, jpeg);
  const JpegImage img = decode_jpeg(jpeg);
  EXPECT_NEAR(img.pixels[w * h / 2], 125, 1);
}

TEST(Jpeg, MalformedInputIsRefusedNamingWhatIsWrong) {
  JpegEncoder enc;
  std::vector<std::uint8_t> out, px(10);
  EXPECT_THROW(enc.encode({4, 4, 1, 8, px}, 90, out), InvalidInput);  // 10 bytes for 16 pixels
  EXPECT_THROW(enc.encode({2, 5, 2, 8, px}, 90, out), InvalidInput);  // 2 channels
  EXPECT_THROW(enc.encode({2, 5, 1, 8, px}, 0, out), InvalidInput);   // quality
  const std::vector<std::uint8_t> junk = {1, 2, 3, 4, 5};
  try {
    decode_jpeg(junk);
    FAIL();
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("FF D8"), std::string::npos) << e.what();
  }
  const std::vector<std::uint8_t> truncated = {0xFF, 0xD8, 0xFF, 0xE0, 0, 0};
  EXPECT_THROW(decode_jpeg(truncated), InvalidInput);
}

}  // namespace
}  // namespace mc
