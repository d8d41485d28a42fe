#include "microcobot/core/zstd.h"

#include <zstd.h>

#include <fmt/format.h>

#include "microcobot/core/error.h"

namespace mc {

void zstd_compress(std::string_view in, int level, std::string& out) {
  require(level >= 1 && level <= 19, "zstd level", "must be within [1, 19]", level);
  out.resize(ZSTD_compressBound(in.size()));
  // The simple API writes the content size into the frame header (ZSTD_c_contentSizeFlag is on
  // by default), so a reader can check it before it allocates.
  const std::size_t n = ZSTD_compress(out.data(), out.size(), in.data(), in.size(), level);
  if (ZSTD_isError(n))
    throw Error(ExitCode::kComputationFailed,
                std::string("zstd: compression failed: ") + ZSTD_getErrorName(n));
  out.resize(n);
}

std::string zstd_decompress(std::string_view in, std::size_t expected_size, const std::string& name,
                            std::size_t max_size) {
  if (expected_size > max_size) {
    throw InvalidInput(name, 0,
                       fmt::format("zstd data claims {} bytes uncompressed, more than the {} read at most",
                                   expected_size, max_size));
  }
  // One byte of room beyond the expected size tells "exactly" from "more".
  std::string out(expected_size + 1, '\0');
  const std::size_t n = ZSTD_decompress(out.data(), out.size(), in.data(), in.size());
  if (ZSTD_isError(n)) throw InvalidInput(name, 0, std::string("zstd data corrupt: ") + ZSTD_getErrorName(n));
  if (n != expected_size) {
    throw InvalidInput(name, 0,
                       fmt::format("zstd data expands to {} bytes, not the {} stated", n, expected_size));
  }
  out.resize(n);
  return out;
}

}  // namespace mc
