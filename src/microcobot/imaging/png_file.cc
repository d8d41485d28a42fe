#include "microcobot/imaging/png_file.h"

#include <cmath>
#include <csetjmp>
#include <cstdint>
#include <vector>

#include <png.h>

#include "microcobot/core/error.h"
#include "microcobot/core/staged_file.h"

namespace mc::imaging {

namespace {

void append(png_structp png, png_bytep data, png_size_t length) {
  auto* out = static_cast<std::string*>(png_get_io_ptr(png));
  out->append(reinterpret_cast<const char*>(data), length);
}

void flush(png_structp) {}

// A cross of +-`arm` pixels at (u, v), drawn in `value`, clipped to the frame.
void draw_cross(Frame& f, double u, double v, int arm, std::uint16_t value) {
  const int cu = static_cast<int>(std::lround(u)), cv = static_cast<int>(std::lround(v));
  for (int d = -arm; d <= arm; ++d) {
    if (cv >= 0 && cv < f.height && cu + d >= 0 && cu + d < f.width)
      f.pixels[static_cast<std::size_t>(cv) * f.width + cu + d] = value;
    if (cu >= 0 && cu < f.width && cv + d >= 0 && cv + d < f.height)
      f.pixels[static_cast<std::size_t>(cv + d) * f.width + cu] = value;
  }
}

}  // namespace

std::string encode_marked_png(const Frame& frame, double feature_u_px, double feature_v_px,
                              double target_u_px, double target_v_px) {
  Frame marked = frame;
  draw_cross(marked, target_u_px, target_v_px, 12,
             static_cast<std::uint16_t>(marked.pixels.empty() ? 0 : (1 << marked.bit_depth) - 1));
  draw_cross(marked, feature_u_px, feature_v_px, 8, 0);
  return encode_png(marked);
}

std::string encode_png(const Frame& frame) {
  const bool eight = frame.bit_depth <= 8;
  std::string out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (!png) throw ComputationFailed("PNG: cannot create the encoder");
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    throw ComputationFailed("PNG: cannot create the encoder");
  }
  // Rows converted before libpng's setjmp region, so that nothing needing destruction lives in it.
  const std::size_t row_bytes = static_cast<std::size_t>(frame.width) * (eight ? 1 : 2);
  std::vector<png_byte> bytes(row_bytes * static_cast<std::size_t>(frame.height));
  for (std::size_t i = 0; i < frame.pixels.size(); ++i) {
    const std::uint16_t v = frame.pixels[i];
    if (eight) {
      bytes[i] = static_cast<png_byte>(v);
    } else {
      bytes[2 * i] = static_cast<png_byte>(v >> 8);  // PNG is big-endian
      bytes[2 * i + 1] = static_cast<png_byte>(v & 0xff);
    }
  }
  std::vector<png_bytep> rows(static_cast<std::size_t>(frame.height));
  for (int r = 0; r < frame.height; ++r) rows[r] = bytes.data() + static_cast<std::size_t>(r) * row_bytes;
  png_color_8 sig{};
  sig.gray = static_cast<png_byte>(frame.bit_depth);
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw ComputationFailed("PNG: libpng failed to encode the frame");
  }
  png_set_write_fn(png, &out, append, flush);
  png_set_IHDR(png, info, static_cast<png_uint_32>(frame.width), static_cast<png_uint_32>(frame.height),
               eight ? 8 : 16, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_set_sBIT(png, info, &sig);
  png_set_compression_level(png, 3);  // fast: a camera's snapshots, not an archive
  png_set_rows(png, info, rows.data());
  png_write_png(png, info, PNG_TRANSFORM_IDENTITY, nullptr);
  png_destroy_write_struct(&png, &info);
  return out;
}

void write_png(const std::filesystem::path& path, const Frame& frame) {
  const std::string bytes = encode_png(frame);
  StagedFile file(path);
  file.write(bytes);
  file.commit();
}

}  // namespace mc::imaging
