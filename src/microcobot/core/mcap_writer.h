#pragma once
/// @file
/// An MCAP writer (https://mcap.dev/spec, major version 0), written from the specification:
/// no MCAP package exists for Debian. It writes indexed files that viewers (Foxglove,
/// Lichtblick, `@mcap/core`'s McapIndexedReader) can seek in:
///
///     magic Header  Schema* Channel*  (Chunk MessageIndex* | Metadata | Attachment)*  DataEnd
///     Summary: Schema* Channel* Statistics ChunkIndex* AttachmentIndex* MetadataIndex*
///              SummaryOffset*   Footer magic
///
/// Messages go into chunks of about `chunk_target_bytes` of records, stored as they are or
/// compressed with zstd (spec, "Chunk": `compression` "zstd", `uncompressed_size`, and
/// `uncompressed_crc` the CRC-32 of the records before compression); each chunk is followed by
/// one MessageIndex per channel it holds, whose offsets count in the uncompressed records. The
/// data section's and the summary's CRCs are written too.
///
/// The file is written under a temporary name beside the target and renamed at close(), so an
/// interrupted run never leaves a partial file under the final name (docs/architecture.md, errors).
/// Not for the real-time path (it does I/O and compresses: a live recording writes it from a
/// thread of its own, live/session_recording.h), but a message costs no allocation once the
/// chunk buffers have grown to their size.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "microcobot/core/staged_file.h"

namespace mc {

/// CRC-32 as zlib's crc32() and MCAP use (ISO-HDLC: reflected polynomial 0xEDB88320, initial
/// value and final XOR 0xFFFFFFFF). Chains like zlib: crc32(b, crc32(a)) == crc32(a + b);
/// start with 0.
std::uint32_t crc32(std::string_view bytes, std::uint32_t previous = 0);

/// The record opcodes of MCAP version 0 (spec, "Records").
enum class McapOpcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

/// The 8 bytes that open and close every MCAP file: "\x89MCAP0\r\n".
inline constexpr std::string_view kMcapMagic{"\x89MCAP0\r\n", 8};

/// How chunks are stored: as they are, or compressed with zstd (core/zstd.h) at a level.
struct McapCompression {
  bool zstd = false;
  int zstd_level = 3;  ///< 1..19 (fast .. small)
};

class McapWriter {
 public:
  static constexpr std::size_t kDefaultChunkBytes = std::size_t{1} << 20;

  /// Opens a temporary file beside `path` and writes the magic and the Header (profile "",
  /// library "microcobot"). A chunk is closed once its records reach `chunk_target_bytes`.
  /// Throws InvalidInput naming `path` when the directory is missing or not writable.
  explicit McapWriter(std::filesystem::path path, std::size_t chunk_target_bytes = kDefaultChunkBytes,
                      McapCompression compression = {});
  /// Without close() (an exception unwinding, a cut run) the temporary file is removed and
  /// nothing appears under the target name.
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  /// Also closes a chunk when a message comes `span_ns` or more of log time after its first, and
  /// then writes the file through to the operating system, so that a writer that dies (a crash,
  /// kill -9) leaves every chunk but the open one readable (core/mcap_recover.h). 0 (the
  /// default): by size alone.
  /// With a span, a failed write keeps the file for close_at_last_chunk() (StagedFile::keep_on_failure).
  void set_chunk_max_span_ns(std::uint64_t span_ns);
  /// After a failed write (a full disk) of a writer with a chunk span: cuts the file back to the
  /// last chunk written through and closes it there (DataEnd, summary, renamed to its name), so
  /// it is a readable recording of everything up to that chunk. Returns the messages kept. When
  /// even that cannot be written, throws InvalidInput and leaves the temporary, whose whole
  /// chunks a recovery reads (core/mcap_recover.h).
  std::uint64_t close_at_last_chunk();

  /// Adds a Schema record (e.g. encoding "jsonschema", data the JSON Schema text). Returns its
  /// id: 1, 2, ... (0 means "no schema" in MCAP).
  std::uint16_t add_schema(std::string_view name, std::string_view encoding, std::string_view data);
  /// Adds a Channel record on schema `schema_id` (0 for none, else an id add_schema returned)
  /// with `message_encoding` (e.g. "json"). Returns its id: 1, 2, ... Throws InvalidInput on
  /// an unknown schema id.
  std::uint16_t add_channel(std::uint16_t schema_id, std::string_view topic,
                            std::string_view message_encoding,
                            const std::vector<std::pair<std::string, std::string>>& metadata = {});

  /// Adds a Metadata record (spec, "Metadata": a name and a string map, e.g. the program's
  /// version), listed in the summary by a MetadataIndex. Throws InvalidInput after close().
  void add_metadata(std::string_view name, const std::vector<std::pair<std::string, std::string>>& entries);
  /// Adds an Attachment record (spec, "Attachment": a named file with its media type, e.g. the
  /// configuration as "application/yaml"), its CRC-32 and an AttachmentIndex in the summary.
  void add_attachment(std::string_view name, std::string_view media_type, std::string_view data,
                      std::uint64_t log_time_ns, std::uint64_t create_time_ns);

  /// Writes one message on `channel_id`; times in nanoseconds. Throws InvalidInput on an
  /// unknown channel or a failed write.
  void write(std::uint16_t channel_id, std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
             std::string_view payload);
  void write(std::uint16_t channel_id, std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
             std::span<const std::byte> payload);

  /// Closes the last chunk, writes DataEnd, the summary, the summary offsets, the footer and
  /// the closing magic, flushes and renames the file to its target name. Throws InvalidInput
  /// naming the file when a write fails (the temporary file is then removed). Idempotent.
  void close();

  const std::filesystem::path& path() const { return path_; }
  std::uint64_t message_count() const { return message_count_; }
  std::size_t chunk_count() const { return chunk_indexes_.count; }
  /// The memory the summary's chunk index holds (bytes reserved): the one part of a writer's
  /// memory that grows with the recording, about 80 bytes and 10 per channel in a chunk, each
  /// chunk's ChunkIndex record kept as the bytes the summary will hold.
  std::size_t chunk_index_bytes() const { return chunk_indexes_.reserved(); }
  /// Chunk records written so far, before and after compression (equal when uncompressed).
  std::uint64_t records_bytes() const { return records_bytes_; }
  std::uint64_t stored_bytes() const { return stored_bytes_; }

 private:
  // The ChunkIndex records for the summary, serialised as each chunk closes (opcode, length,
  // content) into blocks of a fixed size: no allocation per chunk, and no more than a block
  // reserved beyond what the records take however long the recording.
  struct ChunkIndexLog {
    static constexpr std::size_t kBlockBytes = std::size_t{64} << 10;
    struct Mark {
      std::size_t count = 0, blocks = 0, last_size = 0;
    };
    std::vector<std::string> blocks;
    std::size_t count = 0;
    void append(std::string_view record);
    Mark mark() const { return {count, blocks.size(), blocks.empty() ? 0 : blocks.back().size()}; }
    void truncate(const Mark& m);
    std::size_t reserved() const;
  };
  struct ChannelState {
    std::string record;  // the Channel record's content, repeated in the summary
    std::uint64_t count = 0;
    std::vector<std::pair<std::uint64_t, std::uint64_t>> index;  // this chunk: log time, offset
  };

  std::uint64_t position() const { return flushed_ + out_.size(); }
  void take_checkpoint();            // the state after the last chunk written through
  void put(std::string_view bytes);  // to the file (buffered); CRC'd while in the data section
  void put_record(McapOpcode op, std::string_view content);
  void flush_buffer();
  void close_chunk();

  struct IndexEntry {  // an AttachmentIndex or MetadataIndex record's content
    McapOpcode op;
    std::string content;
  };

  std::filesystem::path path_;
  StagedFile file_;
  std::size_t chunk_target_;
  std::uint64_t chunk_span_ns_ = 0;
  McapCompression compression_;
  std::string compressed_;     // the chunk's records, compressed
  std::string out_;            // bytes not yet written to file_
  std::uint64_t flushed_ = 0;  // bytes written to file_
  bool in_data_ = true;
  std::uint32_t data_crc_ = 0;

  std::vector<std::string> schemas_;    // Schema record contents, id - 1
  std::vector<ChannelState> channels_;  // id - 1
  std::string chunk_;                   // the open chunk's records
  std::string scratch_;                 // record being assembled
  std::string index_offsets_;           // the closing chunk's message_index_offsets
  std::string chunk_index_record_;      // the closing chunk's ChunkIndex record
  std::uint64_t chunk_start_ns_ = 0, chunk_end_ns_ = 0;
  ChunkIndexLog chunk_indexes_;
  std::vector<IndexEntry> indexes_;  // attachments and metadata, in file order
  std::uint32_t attachment_count_ = 0, metadata_count_ = 0;
  std::uint64_t records_bytes_ = 0, stored_bytes_ = 0;
  std::uint64_t message_count_ = 0;
  std::uint64_t start_ns_ = 0, end_ns_ = 0;
  bool closed_ = false;

  // What close_at_last_chunk() goes back to: the file and the summary's state after the last
  // chunk written through.
  struct Checkpoint {
    std::uint64_t position = 0;
    std::uint32_t data_crc = 0;
    std::size_t schemas = 0, channels = 0, indexes = 0;
    ChunkIndexLog::Mark chunks;
    std::uint32_t attachments = 0, metadata = 0;
    std::uint64_t messages = 0, start_ns = 0, end_ns = 0, records_bytes = 0, stored_bytes = 0;
    std::vector<std::uint64_t> channel_counts;
  };
  Checkpoint checkpoint_;
};

}  // namespace mc
