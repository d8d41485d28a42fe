#include "microcobot/imaging/tiff_file.h"

#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "microcobot/core/error.h"

namespace mc::imaging {

namespace {

// TIFF 6.0 field types (Part 1, section 2) and the tags of a grey baseline image (section 4).
enum TiffType : std::uint16_t { kShort = 3, kLong = 4, kRational = 5, kAscii = 2 };
enum TiffTag : std::uint16_t {
  kImageWidth = 256,
  kImageLength = 257,
  kBitsPerSample = 258,
  kCompression = 259,
  kPhotometric = 262,
  kImageDescription = 270,
  kStripOffsets = 273,
  kSamplesPerPixel = 277,
  kRowsPerStrip = 278,
  kStripByteCounts = 279,
  kMaxSampleValue = 281,
  kXResolution = 282,
  kYResolution = 283,
  kResolutionUnit = 296,
  kSoftware = 305,
};

void put16(std::string& out, std::uint16_t v) {
  out.push_back(static_cast<char>(v & 0xff));
  out.push_back(static_cast<char>(v >> 8));
}
void put32(std::string& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

struct Entry {
  TiffTag tag;
  TiffType type;
  std::uint32_t count;
  std::uint32_t value;  ///< the value itself (fits in 4 bytes) or the offset of its data
};

// A rational as numerator / 1e4-scaled denominator: pixels per cm to 4 significant decimals.
std::pair<std::uint32_t, std::uint32_t> rational(double v) {
  std::uint32_t den = 10000;
  while (den > 1 && v * den > 4.0e9) den /= 10;
  return {static_cast<std::uint32_t>(std::llround(v * den)), den};
}

}  // namespace

std::string encode_tiff(const Frame& frame, double m_per_px, const std::string& description) {
  require(frame.width > 0 && frame.height > 0 &&
              frame.pixels.size() ==
                  static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height),
          "tiff.frame", "must hold width x height pixels", static_cast<double>(frame.pixels.size()));
  require(std::isfinite(m_per_px) && m_per_px >= 0.0, "tiff.m_per_px", "must be >= 0 and finite", m_per_px);
  for (char c : description)
    require(c >= 0x20 && c < 0x7f, "tiff.description", "must be printable ASCII", static_cast<double>(c));
  // Tag data of 4 bytes or fewer would go inside the entry: a short description is padded out.
  std::string text = description;
  if (!text.empty() && text.size() < 4) text.resize(4, ' ');
  const bool wide = frame.bit_depth > 8;
  const std::uint32_t bytes_per_sample = wide ? 2 : 1;
  const std::uint32_t strip_bytes =
      static_cast<std::uint32_t>(frame.pixels.size()) * bytes_per_sample;  // < 4 GiB: 16-bit sensors
  const std::uint16_t max_value = static_cast<std::uint16_t>((1u << frame.bit_depth) - 1u);
  static const std::string software = "microcobot";

  // Layout: header (8) | pixels | description | software | x, y resolution | IFD (word aligned).
  std::vector<Entry> entries;
  const std::uint32_t pixels_at = 8;
  std::uint32_t at = pixels_at + strip_bytes;
  const std::uint32_t description_at = at;
  if (!text.empty()) at += static_cast<std::uint32_t>(text.size()) + 1;
  const std::uint32_t software_at = at;
  at += static_cast<std::uint32_t>(software.size()) + 1;
  at += at % 2;
  const std::uint32_t resolution_at = at;
  if (m_per_px > 0.0) at += 16;
  const std::uint32_t ifd_at = at + at % 2;

  entries.push_back({kImageWidth, kLong, 1, static_cast<std::uint32_t>(frame.width)});
  entries.push_back({kImageLength, kLong, 1, static_cast<std::uint32_t>(frame.height)});
  entries.push_back({kBitsPerSample, kShort, 1, bytes_per_sample * 8});
  entries.push_back({kCompression, kShort, 1, 1});  // none
  entries.push_back({kPhotometric, kShort, 1, 1});  // BlackIsZero
  if (!text.empty())
    entries.push_back(
        {kImageDescription, kAscii, static_cast<std::uint32_t>(text.size()) + 1, description_at});
  entries.push_back({kStripOffsets, kLong, 1, pixels_at});
  entries.push_back({kSamplesPerPixel, kShort, 1, 1});
  entries.push_back({kRowsPerStrip, kLong, 1, static_cast<std::uint32_t>(frame.height)});
  entries.push_back({kStripByteCounts, kLong, 1, strip_bytes});
  entries.push_back({kMaxSampleValue, kShort, 1, max_value});
  if (m_per_px > 0.0) {
    entries.push_back({kXResolution, kRational, 1, resolution_at});
    entries.push_back({kYResolution, kRational, 1, resolution_at + 8});
    entries.push_back({kResolutionUnit, kShort, 1, 3});  // centimetre
  }
  entries.push_back({kSoftware, kAscii, static_cast<std::uint32_t>(software.size()) + 1, software_at});

  std::string out;
  out.reserve(ifd_at + 6 + 12 * entries.size());
  out += "II";
  put16(out, 42);
  put32(out, ifd_at);
  for (std::uint16_t v : frame.pixels) {
    const std::uint16_t clipped = v > max_value ? max_value : v;
    if (wide) {
      put16(out, clipped);
    } else {
      out.push_back(static_cast<char>(clipped));
    }
  }
  if (!text.empty()) out += text + '\0';
  out += software + '\0';
  if (out.size() % 2) out.push_back('\0');
  if (m_per_px > 0.0) {
    const auto [num, den] = rational(0.01 / m_per_px);  // pixels per centimetre
    for (int axis = 0; axis < 2; ++axis) {
      put32(out, num);
      put32(out, den);
    }
  }
  if (out.size() % 2) out.push_back('\0');
  put16(out, static_cast<std::uint16_t>(entries.size()));
  for (const Entry& e : entries) {  // in ascending tag order (section 2: "sorted in ascending order")
    put16(out, e.tag);
    put16(out, e.type);
    put32(out, e.count);
    if (e.type == kShort && e.count == 1) {
      put16(out, static_cast<std::uint16_t>(e.value));  // left-justified in the 4-byte field
      put16(out, 0);
    } else {
      put32(out, e.value);
    }
  }
  put32(out, 0);  // no further image
  return out;
}

}  // namespace mc::imaging
