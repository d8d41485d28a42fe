// The baseline TIFF of a camera frame, read back by a reader written here from TIFF 6.0 Part 1
// (the header, one IFD of 12-byte entries in ascending tag order, values inline when they fit
// in 4 bytes): the pixels, the scale and the description are where the specification puts
// them. Pillow reads the CLI's files independently (tests/python/test_vision.py).

#include "microcobot/imaging/tiff_file.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <string>

#include "microcobot/core/error.h"

namespace mc::imaging {
namespace {

std::uint32_t u16(const std::string& b, std::size_t at) {
  return static_cast<std::uint8_t>(b[at]) | static_cast<std::uint32_t>(static_cast<std::uint8_t>(b[at + 1]))
                                                << 8;
}
std::uint32_t u32(const std::string& b, std::size_t at) { return u16(b, at) | u16(b, at + 2) << 16; }

struct Field {
  std::uint32_t type, count, value;
};

std::map<std::uint32_t, Field> read_ifd(const std::string& b) {
  EXPECT_EQ(b.substr(0, 2), "II");
  EXPECT_EQ(u16(b, 2), 42u);
  const std::uint32_t ifd = u32(b, 4);
  EXPECT_EQ(ifd % 2, 0u) << "the IFD starts on a word boundary";
  const std::uint32_t n = u16(b, ifd);
  std::map<std::uint32_t, Field> out;
  std::uint32_t last = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::size_t e = ifd + 2 + 12 * i;
    const std::uint32_t tag = u16(b, e), type = u16(b, e + 2), count = u32(b, e + 4);
    EXPECT_GT(tag, last) << "tags in ascending order";
    last = tag;
    const bool short_inline = type == 3 && count == 1;
    out[tag] = {type, count, short_inline ? u16(b, e + 8) : u32(b, e + 8)};
  }
  EXPECT_EQ(u32(b, ifd + 2 + 12 * n), 0u) << "one image";
  return out;
}

Frame ramp(int w, int h, int bits) {
  Frame f;
  f.width = w;
  f.height = h;
  f.bit_depth = bits;
  for (int i = 0; i < w * h; ++i) f.pixels.push_back(static_cast<std::uint16_t>((i * 37) % (1 << bits)));
  return f;
}

TEST(TiffFile, A12BitFrameIsSixteenBitGreyWithItsScaleAndDescription) {
  const Frame f = ramp(7, 5, 12);  // odd sizes: the padding before the IFD is exercised
  const std::string b = encode_tiff(f, 0.55e-6, "{\"objective\":\"10x\"}");
  auto ifd = read_ifd(b);
  EXPECT_EQ(ifd[256].value, 7u);
  EXPECT_EQ(ifd[257].value, 5u);
  EXPECT_EQ(ifd[258].value, 16u);
  EXPECT_EQ(ifd[259].value, 1u);  // no compression
  EXPECT_EQ(ifd[262].value, 1u);  // BlackIsZero
  EXPECT_EQ(ifd[277].value, 1u);
  EXPECT_EQ(ifd[281].value, 4095u);
  EXPECT_EQ(ifd[279].value, 2u * 35u);
  const std::uint32_t strip = ifd[273].value;
  for (int i = 0; i < 35; ++i) EXPECT_EQ(u16(b, strip + 2 * i), f.pixels[static_cast<std::size_t>(i)]) << i;
  // 0.55 um per pixel: 18181.8 pixels per centimetre.
  const std::uint32_t x = ifd[282].value;
  EXPECT_NEAR(static_cast<double>(u32(b, x)) / u32(b, x + 4), 0.01 / 0.55e-6, 1e-3);
  EXPECT_EQ(ifd[296].value, 3u);
  const Field d = ifd[270];
  EXPECT_EQ(b.substr(d.value, d.count), std::string("{\"objective\":\"10x\"}") + '\0');
}

TEST(TiffFile, AnEightBitFrameIsOneBytePerPixelAndAShortDescriptionIsNotInlined) {
  const Frame f = ramp(3, 3, 8);
  const std::string b = encode_tiff(f, 0.0, "ab");
  auto ifd = read_ifd(b);
  EXPECT_EQ(ifd[258].value, 8u);
  EXPECT_EQ(ifd[279].value, 9u);
  for (int i = 0; i < 9; ++i)
    EXPECT_EQ(static_cast<std::uint8_t>(b[ifd[273].value + i]), f.pixels[static_cast<std::size_t>(i)]);
  EXPECT_EQ(ifd.count(282), 0u) << "no scale given, no resolution";
  EXPECT_EQ(b.substr(ifd[270].value, ifd[270].count), std::string("ab  ") + '\0');
}

TEST(TiffFile, RefusesAnEmptyFrameABadScaleAndANonAsciiDescription) {
  EXPECT_THROW(encode_tiff(Frame{}, 1e-6, ""), InvalidParams);
  EXPECT_THROW(encode_tiff(ramp(2, 2, 8), -1.0, ""), InvalidParams);
  EXPECT_THROW(encode_tiff(ramp(2, 2, 8), 1e-6, "caf\xc3\xa9"), InvalidParams);
}

}  // namespace
}  // namespace mc::imaging
