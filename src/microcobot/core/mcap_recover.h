#pragma once
/// @file
/// Recovering an MCAP file whose writer never closed it (a crash, kill -9, a full disk): the
/// data section read as far as it is whole, and written again as an indexed file that viewers
/// can seek in (as `mcap recover` does). A live recording closes a chunk at least every second
/// and writes it through (McapWriter::set_chunk_max_span_ns), so what is lost is the chunk that
/// was open: at most its last second.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "microcobot/core/mcap_reader.h"

namespace mc {

/// What an unclosed MCAP file still holds.
struct McapSalvage {
  /// The schemas, channels, messages, metadata and attachments of its whole records (a chunk
  /// counts when its records decompress and match their CRC); no summary.
  McapContents contents;
  std::uint64_t whole_bytes = 0;  ///< the file up to the end of its last whole record
  std::uint64_t file_bytes = 0;
  bool complete = false;  ///< the data section reached DataEnd: nothing was lost
  std::string stopped;    ///< why reading stopped before DataEnd ("" when complete)
};

/// Reads `bytes` (an MCAP file, `name` in messages) record by record up to the first one that
/// is cut or inconsistent. Throws InvalidInput only when it is not an MCAP file at all (no
/// magic, or no Header record after it).
McapSalvage salvage_mcap(std::string_view bytes, const std::string& name);

/// What recover_mcap wrote.
struct McapRecovery {
  McapSalvage salvage;  ///< without its contents' messages (written out)
  std::uint64_t messages = 0;
  double duration_s = 0.0;  ///< from the first message's log time to the last
};

/// Recovers `in` into `out` (a new indexed file: the salvaged schemas, channels, metadata,
/// attachments and messages in their order, zstd chunks when the input's were, and a Metadata
/// record "recovery" naming the input, the bytes kept and why reading stopped). `out` is
/// written atomically. Throws InvalidInput naming the file when `in` cannot be read or is not
/// MCAP, or `out` cannot be written.
McapRecovery recover_mcap(const std::filesystem::path& in, const std::filesystem::path& out);

}  // namespace mc
