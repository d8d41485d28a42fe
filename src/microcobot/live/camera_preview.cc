#include "microcobot/live/camera_preview.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <string>

#include "microcobot/core/error.h"

namespace mc::live {

int CameraPreview::binning(int width_px, int max_width_px) {
  if (width_px <= 0 || max_width_px <= 0)
    throw InvalidInput("camera preview: width " + std::to_string(width_px) + " px for at most " +
                       std::to_string(max_width_px) + " px");
  return (width_px + max_width_px - 1) / max_width_px;
}

namespace {

// Adds one image row's f-sample groups into sums[j * c + k] (w groups of c channels).
template <class Sample>
void add_row(const Sample* row, int w, int f, int c, std::uint32_t* sums) {
  for (int j = 0; j < w; ++j, row += f * c, sums += c)
    for (int q = 0; q < f; ++q)
      for (int k = 0; k < c; ++k) sums[k] += row[q * c + k];
}

}  // namespace

const std::vector<std::uint8_t>& CameraPreview::encode(const devices::Image& image, int quality) {
  if (image.data.size() != image.size_bytes() || image.width <= 0 || image.height <= 0)
    throw InvalidInput("camera preview: " + std::to_string(image.data.size()) + " bytes for a " +
                       std::to_string(image.width) + "x" + std::to_string(image.height) + " image");
  const int f = binning(image.width);
  const int c = image.channels;
  const int w = image.width / f, h = std::max(1, image.height / f);
  const int rows = std::min(f, image.height);  // image rows per binned row
  binned_.resize(w, h, c, 8);
  row_sums_.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(c));
  const bool deep = image.bit_depth > 8;
  const int shift = deep ? image.bit_depth - 8 : 0;
  const std::size_t row_samples = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(c);
  if (deep) deep_row_.resize(row_samples);
  const auto n = static_cast<std::uint32_t>(f * rows);
  for (int i = 0; i < h; ++i) {
    std::fill(row_sums_.begin(), row_sums_.end(), 0u);
    for (int r = 0; r < rows; ++r) {
      const std::uint8_t* row = image.data.data() + static_cast<std::size_t>(i * f + r) * row_samples *
                                                        static_cast<std::size_t>(image.bytes_per_sample());
      if (deep) {
        // Two-byte little-endian samples, as devices::Image keeps them (this host's order).
        static_assert(std::endian::native == std::endian::little);
        std::memcpy(deep_row_.data(), row, row_samples * 2);
        add_row(deep_row_.data(), w, f, c, row_sums_.data());
      } else {
        add_row(row, w, f, c, row_sums_.data());
      }
    }
    std::uint8_t* out = binned_.data.data() + static_cast<std::size_t>(i) * static_cast<std::size_t>(w * c);
    for (std::size_t k = 0; k < row_sums_.size(); ++k) {
      const std::uint32_t mean = ((row_sums_[k] + n / 2) / n) >> shift;  // rounded, then 8 bits
      out[k] = static_cast<std::uint8_t>(std::min<std::uint32_t>(mean, 255u));
    }
  }
  encoder_.encode({binned_.width, binned_.height, binned_.channels, 8, binned_.data}, quality, jpeg_);
  return jpeg_;
}

}  // namespace mc::live
