#pragma once
/// @file
/// A strict MCAP reader (https://mcap.dev/spec, major version 0) for tests and tools: it reads
/// the whole file and checks everything a writer promises, so that a file it accepts is one
/// that indexed viewers can seek in:
///  - both magics, the Header first, the Footer last, every record's framing;
///  - chunks: uncompressed ("") or zstd-compressed ("zstd", core/zstd.h), sizes, the CRC-32 of
///    the (decompressed) records, messages within the chunk's time range, on channels defined
///    before them;
///  - Attachment records' CRC-32; AttachmentIndex and MetadataIndex records that point at the
///    data section's Attachment and Metadata records;
///  - each MessageIndex: it follows its chunk and lists exactly that chunk's messages of its
///    channel (log time and offset);
///  - DataEnd's CRC of the data section, the Footer's CRC of the summary;
///  - the summary: Schema and Channel records equal to the data section's, one ChunkIndex per
///    chunk matching it (offsets, lengths, times, message index offsets), Statistics equal to
///    the counts of the data, SummaryOffset groups that cover records of their opcode.
/// Errors are InvalidInput with one line: "<file>: byte <offset>: <what is wrong>".

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace mc {

struct McapSchema {
  std::uint16_t id = 0;
  std::string name;
  std::string encoding;
  std::string data;
};

struct McapChannel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;
  std::string topic;
  std::string message_encoding;
  std::vector<std::pair<std::string, std::string>> metadata;
};

struct McapMessage {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time_ns = 0;
  std::uint64_t publish_time_ns = 0;
  std::string data;
};

/// A Metadata record: a name and its string map (spec, "Metadata").
struct McapMetadata {
  std::string name;
  std::vector<std::pair<std::string, std::string>> entries;
  /// The value of `key`, or nullptr.
  const std::string* find(std::string_view key) const;
};

/// An Attachment record (spec, "Attachment").
struct McapAttachment {
  std::uint64_t log_time_ns = 0, create_time_ns = 0;
  std::string name, media_type, data;
};

/// How a chunk was stored: its compression ("" or "zstd") and sizes.
struct McapChunkStorage {
  std::string compression;
  std::uint64_t compressed_size = 0, uncompressed_size = 0;
};

/// The Statistics record of the summary.
struct McapStatistics {
  std::uint64_t message_count = 0;
  std::uint16_t schema_count = 0;
  std::uint32_t channel_count = 0;
  std::uint32_t attachment_count = 0;
  std::uint32_t metadata_count = 0;
  std::uint32_t chunk_count = 0;
  std::uint64_t message_start_time_ns = 0;
  std::uint64_t message_end_time_ns = 0;
  std::map<std::uint16_t, std::uint64_t> channel_message_counts;
};

/// The content of an MCAP file, in file order.
struct McapContents {
  std::string profile;
  std::string library;
  std::vector<McapSchema> schemas;
  std::vector<McapChannel> channels;
  std::vector<McapMessage> messages;
  std::vector<McapMetadata> metadata;
  std::vector<McapAttachment> attachments;
  std::vector<McapChunkStorage> chunks;  ///< in file order
  bool has_summary = false;              ///< false for a file without summary (allowed by the spec)
  bool has_statistics = false;           ///< the summary held a Statistics record
  McapStatistics statistics;
  std::size_t chunk_count = 0;

  const McapChannel* channel(std::uint16_t id) const;
  const McapSchema* schema(std::uint16_t id) const;
  /// The first Metadata record named `name`, or nullptr.
  const McapMetadata* find_metadata(std::string_view name) const;
};

/// Reads and checks `file`. Throws InvalidInput "<file>: byte <offset>: <what>" on any
/// inconsistency, and when the file cannot be read.
McapContents read_mcap(const std::filesystem::path& file);
/// The same on bytes in memory; `name` stands for the file in messages.
McapContents parse_mcap(std::string_view bytes, const std::string& name);

}  // namespace mc
