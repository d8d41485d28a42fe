#include "microcobot/core/jpeg.h"

#include <string>

#include <turbojpeg.h>

#include "microcobot/core/error.h"

namespace mc {
namespace {

std::string tj_error(void* handle) { return tjGetErrorStr2(static_cast<tjhandle>(handle)); }

}  // namespace

JpegEncoder::JpegEncoder() : handle_(tjInitCompress()) {
  if (handle_ == nullptr) throw ComputationFailed("jpeg: libjpeg-turbo's compressor could not be created");
}

JpegEncoder::~JpegEncoder() { tjDestroy(static_cast<tjhandle>(handle_)); }

void JpegEncoder::encode(const JpegInput& in, int quality, std::vector<std::uint8_t>& out) {
  if (in.width <= 0 || in.height <= 0 || in.width > 65500 || in.height > 65500)
    throw InvalidInput("jpeg: image size " + std::to_string(in.width) + "x" + std::to_string(in.height) +
                       " is outside 1..65500 pixels");
  if (in.channels != 1 && in.channels != 3)
    throw InvalidInput("jpeg: " + std::to_string(in.channels) + " channels (1 grey or 3 RGB)");
  if (in.bit_depth < 8 || in.bit_depth > 16)
    throw InvalidInput("jpeg: bit depth " + std::to_string(in.bit_depth) + " (8 to 16)");
  if (quality < 1 || quality > 100)
    throw InvalidInput("jpeg: quality " + std::to_string(quality) + " (1 to 100)");
  const std::size_t samples = static_cast<std::size_t>(in.width) * static_cast<std::size_t>(in.height) *
                              static_cast<std::size_t>(in.channels);
  const std::size_t bytes = samples * (in.bit_depth > 8 ? 2u : 1u);
  if (in.data.size() != bytes)
    throw InvalidInput("jpeg: " + std::to_string(in.data.size()) + " bytes of samples for a " +
                       std::to_string(in.width) + "x" + std::to_string(in.height) + " image of " +
                       std::to_string(in.channels) + " channel(s) (expected " + std::to_string(bytes) + ")");
  const std::uint8_t* src = in.data.data();
  if (in.bit_depth > 8) {
    // JPEG (baseline) is 8-bit: the top 8 bits of the sensor's depth.
    scratch_.resize(samples);
    const int shift = in.bit_depth - 8;
    for (std::size_t i = 0; i < samples; ++i) {
      const unsigned v = static_cast<unsigned>(src[2 * i]) | (static_cast<unsigned>(src[2 * i + 1]) << 8);
      const unsigned s = v >> shift;
      scratch_[i] = static_cast<std::uint8_t>(s > 255u ? 255u : s);
    }
    src = scratch_.data();
  }
  const unsigned long max_size = tjBufSize(in.width, in.height, in.channels == 1 ? TJSAMP_GRAY : TJSAMP_420);
  out.resize(max_size);
  unsigned char* dst = out.data();
  unsigned long size = max_size;
  const int rc = tjCompress2(static_cast<tjhandle>(handle_), src, in.width, 0, in.height,
                             in.channels == 1 ? TJPF_GRAY : TJPF_RGB, &dst, &size,
                             in.channels == 1 ? TJSAMP_GRAY : TJSAMP_420, quality, TJFLAG_NOREALLOC);
  if (rc != 0) throw ComputationFailed("jpeg: encoding failed: " + tj_error(handle_));
  out.resize(size);
}

JpegImage decode_jpeg(std::span<const std::uint8_t> jpeg, int channels) {
  if (channels != 1 && channels != 3)
    throw InvalidInput("jpeg: decode to 1 or 3 channels, not " + std::to_string(channels));
  if (jpeg.size() < 4 || jpeg[0] != 0xFF || jpeg[1] != 0xD8)
    throw InvalidInput("jpeg: " + std::to_string(jpeg.size()) +
                       " bytes that do not start with a JPEG marker (FF D8)");
  tjhandle h = tjInitDecompress();
  if (h == nullptr) throw ComputationFailed("jpeg: libjpeg-turbo's decompressor could not be created");
  JpegImage img;
  int subsamp = 0, colorspace = 0;
  if (tjDecompressHeader3(h, jpeg.data(), static_cast<unsigned long>(jpeg.size()), &img.width, &img.height,
                          &subsamp, &colorspace) != 0) {
    const std::string why = tj_error(h);
    tjDestroy(h);
    throw InvalidInput("jpeg: unreadable header: " + why);
  }
  img.channels = channels;
  img.pixels.resize(static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height) *
                    static_cast<std::size_t>(channels));
  const int rc = tjDecompress2(h, jpeg.data(), static_cast<unsigned long>(jpeg.size()), img.pixels.data(),
                               img.width, 0, img.height, channels == 1 ? TJPF_GRAY : TJPF_RGB, 0);
  const std::string why = rc != 0 ? tj_error(h) : std::string();
  tjDestroy(h);
  if (rc != 0) throw InvalidInput("jpeg: cannot decode: " + why);
  return img;
}

}  // namespace mc
