#include "microcobot/devices/grey_frame.h"

#include <algorithm>
#include <bit>
#include <cstring>

namespace mc::devices {

bool to_grey_frame(const Image& img, std::uint64_t frame_index, imaging::Frame& f) {
  if (img.width <= 0 || img.height <= 0 || img.channels < 1 || img.data.size() != img.size_bytes())
    return false;
  f.width = img.width;
  f.height = img.height;
  f.bit_depth = img.bit_depth;
  f.frame_index = frame_index;
  const std::size_t n = static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height);
  f.pixels.resize(n);
  const auto c = static_cast<std::size_t>(img.channels);
  if (img.channels == 1 && img.bit_depth > 8) {
    static_assert(std::endian::native == std::endian::little);  // Image keeps them little-endian
    std::memcpy(f.pixels.data(), img.data.data(), 2 * n);
  } else if (img.channels == 1) {
    std::copy(img.data.begin(), img.data.end(), f.pixels.begin());
  } else {
    for (std::size_t i = 0; i < n; ++i) {
      unsigned sum = 0;
      for (std::size_t k = 0; k < c; ++k) {
        const std::size_t at = i * c + k;
        sum += img.bit_depth > 8 ? (img.data[2 * at] | (static_cast<unsigned>(img.data[2 * at + 1]) << 8))
                                 : img.data[at];
      }
      f.pixels[i] =
          static_cast<std::uint16_t>((sum + static_cast<unsigned>(c) / 2) / static_cast<unsigned>(c));
    }
  }
  return true;
}

}  // namespace mc::devices
