#pragma once
/// @file
/// The MCAP reader's parser (core/mcap_reader.h), shared by its two files: mcap_reader.cc reads
/// the data section (records, chunks, message indexes), mcap_summary.cc checks the summary against
/// it. Internal to core/; include mcap_reader.h instead.

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "microcobot/core/mcap_reader.h"
#include "microcobot/core/mcap_recover.h"
#include "microcobot/core/mcap_writer.h"

namespace mc::mcap_detail {

using Op = McapOpcode;
inline constexpr std::uint64_t kPrefix = 9;       // opcode + content length
inline constexpr std::uint64_t kFooterSize = 29;  // prefix + summary_start, summary_offset_start, crc

/// "Schema", "Chunk", ... or "opcode 0x..".
std::string op_name(std::uint8_t op);

/// Throws InvalidInput "<name>: byte <offset>: <what>".
[[noreturn]] void fail(const std::string& name, std::uint64_t offset, const std::string& what);

/// Reads little-endian fields of one record's content [begin, end); any read past the end is
/// an error naming the record and the field.
class Fields {
 public:
  Fields(std::string_view file, const std::string& name, std::uint64_t begin, std::uint64_t end,
         std::string_view record)
      : file_(file), name_(name), pos_(begin), end_(end), record_(record) {}

  std::uint64_t pos() const { return pos_; }
  std::uint64_t remaining() const { return end_ - pos_; }
  std::uint8_t u8(const char* field) { return static_cast<std::uint8_t>(uint(1, field)); }
  std::uint16_t u16(const char* field) { return static_cast<std::uint16_t>(uint(2, field)); }
  std::uint32_t u32(const char* field) { return static_cast<std::uint32_t>(uint(4, field)); }
  std::uint64_t u64(const char* field) { return uint(8, field); }
  std::string_view bytes(std::uint64_t n, const char* field) {
    need(n, field);
    const auto v = file_.substr(pos_, n);
    pos_ += n;
    return v;
  }
  /// String, Bytes, Map and Array fields: a uint32 length, then that many bytes.
  std::string_view prefixed(const char* field) { return bytes(u32(field), field); }

 private:
  void need(std::uint64_t n, const char* field) {
    if (n > end_ - pos_) {
      fail(name_, pos_,
           fmt::format("{} record: field {} needs {} bytes, {} left in the record", record_, field, n,
                       end_ - pos_));
    }
  }
  std::uint64_t uint(int n, const char* field) {
    need(static_cast<std::uint64_t>(n), field);
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= std::uint64_t{static_cast<std::uint8_t>(file_[pos_ + i])} << (8 * i);
    pos_ += static_cast<std::uint64_t>(n);
    return v;
  }

  std::string_view file_;
  const std::string& name_;
  std::uint64_t pos_, end_;
  std::string_view record_;
};

struct Record {
  std::uint8_t op;
  std::uint64_t offset;   // of the opcode
  std::uint64_t content;  // of the content
  std::uint64_t end;      // one past the content
};

struct ChunkInfo {
  std::uint64_t offset = 0, length = 0, start_ns = 0, end_ns = 0, records_size = 0, stored_size = 0;
  std::string compression;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> messages;  // time, offset
  std::map<std::uint16_t, std::uint64_t> index_offsets;  // MessageIndex records that followed
  std::uint64_t index_start = 0, index_end = 0;
};

struct IndexTarget {  // an Attachment or Metadata record that an index must point at
  std::uint64_t offset, length;
  std::string name;
};

class Parser {
 public:
  Parser(std::string_view bytes, const std::string& name) : f_(bytes), name_(name), file_name_(name) {}

  /// Parses and checks the whole file (throws InvalidInput).
  McapContents run();
  /// Reads the data section up to its first cut or inconsistent record (mcap_salvage.cc).
  McapSalvage salvage();

 private:
  // The record at `at`, which must end by `limit`.
  Record frame(std::uint64_t at, std::uint64_t limit, const char* where);
  McapSchema parse_schema(const Record& r);
  McapChannel parse_channel(const Record& r);
  void define_schema(const Record& r);
  void define_channel(const Record& r);
  const McapMessage& message(const Record& r);
  void chunk(const Record& r);
  void message_index(const Record& r, ChunkInfo& ci);
  // A data-section record with content (Schema, Channel, Message, Chunk, Attachment, Metadata):
  // read, and true; else false.
  bool content_record(const Record& r);
  // Fails on a record that belongs to the summary (Header, Footer, the indexes, Statistics).
  void summary_only(const Record& r);
  // The Header record after the opening magic. Returns the offset just past it.
  std::uint64_t read_header();
  // The data section, from the Header to DataEnd. Returns the offset just past DataEnd.
  std::uint64_t read_data();
  void read_summary(std::uint64_t data_end);
  void metadata(const Record& r);
  void attachment(const Record& r);
  // An index record of the summary must point at the next Attachment/Metadata record, by name.
  void check_index(const Record& r, const char* what, std::uint64_t offset, std::uint64_t length,
                   const std::string& name, const std::vector<IndexTarget>& targets, std::size_t& n);
  void attachment_index(const Record& r);
  void metadata_index(const Record& r);
  void statistics(const Record& r);
  void chunk_index(const Record& r, const ChunkInfo& ci);

  std::string_view f_;  // the file; a decompressed chunk's records while they are parsed
  std::string name_;    // the file's name; with the chunk's offset while its records are parsed
  std::string file_name_;
  std::vector<IndexTarget> attachment_records_, metadata_records_;
  std::size_t attachment_indexes_ = 0, metadata_indexes_ = 0;
  std::uint64_t footer_ = 0, summary_start_ = 0, summary_offset_start_ = 0;
  std::uint32_t summary_crc_ = 0;
  std::vector<ChunkInfo> chunks_;
  std::map<std::uint16_t, std::uint64_t> counts_;
  std::uint64_t attachments_ = 0, metadata_ = 0;
  McapContents out_;
};

}  // namespace mc::mcap_detail
