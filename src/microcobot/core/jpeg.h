#pragma once
/// @file
/// JPEG in and out through libjpeg-turbo's TurboJPEG API (Debian libturbojpeg0-dev): the
/// camera's frames for the console, Foxglove, ROS 2 and the recordings. Encoding a 1280x1024
/// mono frame takes a few milliseconds: it runs on the camera's thread, never on the loop.

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace mc {

/// Samples to encode: rows top to bottom, 1 (grey) or 3 (RGB) channels, `bit_depth` 8 (one
/// byte a sample) or 9-16 (two bytes, little-endian; scaled to 8 bits for JPEG).
struct JpegInput {
  int width = 0;
  int height = 0;
  int channels = 1;
  int bit_depth = 8;
  std::span<const std::uint8_t> data;
};

/// A reusable encoder (one per thread: it keeps libjpeg-turbo's state and a scratch buffer).
class JpegEncoder {
 public:
  JpegEncoder();
  ~JpegEncoder();
  JpegEncoder(const JpegEncoder&) = delete;
  JpegEncoder& operator=(const JpegEncoder&) = delete;

  /// Encodes `in` at `quality` (1..100) into `out` (resized; reused). Throws mc::InvalidInput
  /// on a malformed input (sizes, channels, depth) and mc::Error when libjpeg-turbo fails.
  void encode(const JpegInput& in, int quality, std::vector<std::uint8_t>& out);

 private:
  void* handle_ = nullptr;
  std::vector<std::uint8_t> scratch_;  // 16-bit samples scaled to 8
};

/// A decoded JPEG: 8-bit samples, `channels` 1 (grey) or 3 (RGB).
struct JpegImage {
  int width = 0;
  int height = 0;
  int channels = 1;
  std::vector<std::uint8_t> pixels;
};

/// Decodes a JPEG into grey (channels 1) or RGB (3). Throws mc::InvalidInput naming what is
/// wrong when the bytes are not a JPEG libjpeg-turbo can decode.
JpegImage decode_jpeg(std::span<const std::uint8_t> jpeg, int channels = 1);

}  // namespace mc
