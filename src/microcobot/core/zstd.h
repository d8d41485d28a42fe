#pragma once
/// @file
/// Zstandard (RFC 8878) compression of whole buffers, over Debian's libzstd: the codec MCAP
/// names "zstd" for its chunks (https://mcap.dev/spec, "Chunk"). One frame per buffer, with its
/// content size in the frame header, as the MCAP readers (Foxglove's @foxglove/wasm-zstd,
/// `mcap` CLI) expect.

#include <cstddef>
#include <string>
#include <string_view>

namespace mc {

/// Compresses `in` into one zstd frame at `level` (1 fast .. 19 small; a live recording uses 1:
/// live/session_recording.h says why). Replaces `out`'s content (reuse it: no allocation once
/// it is large enough). Throws InvalidParams for a level outside [1, 19], mc::Error when libzstd
/// fails (out of memory).
void zstd_compress(std::string_view in, int level, std::string& out);

/// Decompresses one or more zstd frames that must expand to exactly `expected_size` bytes (the
/// size MCAP stores beside the compressed bytes). Throws InvalidInput "<name>: <why>" on corrupt
/// data or a size that differs, and when `expected_size` exceeds `max_size` (a hostile file
/// asking for gigabytes).
std::string zstd_decompress(std::string_view in, std::size_t expected_size, const std::string& name,
                            std::size_t max_size = std::size_t{1} << 30);

}  // namespace mc
