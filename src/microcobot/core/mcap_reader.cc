#include "microcobot/core/mcap_reader.h"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <optional>
#include <tuple>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/core/mcap_writer.h"
#include "microcobot/core/zstd.h"

namespace mc {

const McapChannel* McapContents::channel(std::uint16_t id) const {
  for (const auto& c : channels)
    if (c.id == id) return &c;
  return nullptr;
}

const McapSchema* McapContents::schema(std::uint16_t id) const {
  for (const auto& s : schemas)
    if (s.id == id) return &s;
  return nullptr;
}

const McapMetadata* McapContents::find_metadata(std::string_view name) const {
  for (const auto& m : metadata)
    if (m.name == name) return &m;
  return nullptr;
}

const std::string* McapMetadata::find(std::string_view key) const {
  for (const auto& [k, v] : entries)
    if (k == key) return &v;
  return nullptr;
}

namespace {

using Op = McapOpcode;
constexpr std::uint64_t kPrefix = 9;       // opcode + content length
constexpr std::uint64_t kFooterSize = 29;  // prefix + summary_start, summary_offset_start, crc

std::string op_name(std::uint8_t op) {
  static constexpr const char* kNames[] = {"?",          "Header",        "Footer",          "Schema",
                                           "Channel",    "Message",       "Chunk",           "MessageIndex",
                                           "ChunkIndex", "Attachment",    "AttachmentIndex", "Statistics",
                                           "Metadata",   "MetadataIndex", "SummaryOffset",   "DataEnd"};
  if (op >= 1 && op <= 0x0F) return kNames[op];
  return fmt::format("opcode 0x{:02x}", op);
}

[[noreturn]] void fail(const std::string& name, std::uint64_t offset, const std::string& what) {
  throw InvalidInput(name, 0, fmt::format("byte {}: {}", offset, what));
}

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

  McapContents run() {
    const std::uint64_t size = f_.size();
    constexpr std::uint64_t kMin = 8 + kPrefix + 8 + kFooterSize + 8;  // magic, empty header, footer, magic
    if (size < kMin) {
      fail(name_, size,
           fmt::format("truncated: {} bytes is too short for an MCAP file (at least {})", size, kMin));
    }
    if (f_.substr(0, 8) != kMcapMagic) fail(name_, 0, "not an MCAP file (bad opening magic)");
    if (f_.substr(size - 8) != kMcapMagic) {
      fail(name_, size - 8, "bad closing magic (file truncated or never closed)");
    }
    footer_ = size - 8 - kFooterSize;
    {
      const Record r = frame(footer_, size - 8, "footer");
      if (r.op != static_cast<std::uint8_t>(Op::kFooter) || r.end != size - 8) {
        fail(name_, footer_,
             fmt::format("expected the Footer record before the closing magic, found {}", op_name(r.op)));
      }
      Fields fl(f_, name_, r.content, r.end, "Footer");
      summary_start_ = fl.u64("summary_start");
      summary_offset_start_ = fl.u64("summary_offset_start");
      summary_crc_ = fl.u32("summary_crc");
    }
    const std::uint64_t data_end = read_data();
    read_summary(data_end);
    return std::move(out_);
  }

 private:
  // The record at `at`, which must end by `limit`.
  Record frame(std::uint64_t at, std::uint64_t limit, const char* where) {
    if (limit < at || limit - at < kPrefix) {
      fail(name_, at, fmt::format("truncated record header in the {} ({} bytes left)", where, limit - at));
    }
    Record r{};
    r.op = static_cast<std::uint8_t>(f_[at]);
    r.offset = at;
    r.content = at + kPrefix;
    std::uint64_t len = 0;
    for (int i = 0; i < 8; ++i) len |= std::uint64_t{static_cast<std::uint8_t>(f_[at + 1 + i])} << (8 * i);
    if (len > limit - r.content) {
      fail(name_, at,
           fmt::format("{} record of {} bytes runs past the end of the {} ({} bytes left)", op_name(r.op),
                       len, where, limit - r.content));
    }
    r.end = r.content + len;
    return r;
  }

  McapSchema parse_schema(const Record& r) {
    Fields fl(f_, name_, r.content, r.end, "Schema");
    McapSchema s;
    s.id = fl.u16("id");
    s.name = fl.prefixed("name");
    s.encoding = fl.prefixed("encoding");
    s.data = fl.prefixed("data");
    if (s.id == 0) fail(name_, r.offset, "Schema record with id 0 (reserved for \"no schema\")");
    return s;
  }

  McapChannel parse_channel(const Record& r) {
    Fields fl(f_, name_, r.content, r.end, "Channel");
    McapChannel c;
    c.id = fl.u16("id");
    c.schema_id = fl.u16("schema_id");
    c.topic = fl.prefixed("topic");
    c.message_encoding = fl.prefixed("message_encoding");
    const std::uint64_t map_at = fl.pos() + 4;
    const std::string_view map = fl.prefixed("metadata");
    Fields m(f_, name_, map_at, map_at + map.size(), "Channel metadata");
    while (m.remaining() > 0) {
      std::string k(m.prefixed("metadata key"));
      std::string v(m.prefixed("metadata value"));
      c.metadata.emplace_back(std::move(k), std::move(v));
    }
    return c;
  }

  void define_schema(const Record& r) {
    McapSchema s = parse_schema(r);
    if (const auto* old = out_.schema(s.id)) {
      if (old->name != s.name || old->encoding != s.encoding || old->data != s.data) {
        fail(name_, r.offset, fmt::format("Schema {} redefined differently", s.id));
      }
      return;
    }
    out_.schemas.push_back(std::move(s));
  }

  void define_channel(const Record& r) {
    McapChannel c = parse_channel(r);
    if (c.schema_id != 0 && out_.schema(c.schema_id) == nullptr) {
      fail(
          name_, r.offset,
          fmt::format("Channel {} ('{}') uses schema {}, not defined before it", c.id, c.topic, c.schema_id));
    }
    if (const auto* old = out_.channel(c.id)) {
      if (old->schema_id != c.schema_id || old->topic != c.topic ||
          old->message_encoding != c.message_encoding || old->metadata != c.metadata) {
        fail(name_, r.offset, fmt::format("Channel {} redefined differently", c.id));
      }
      return;
    }
    out_.channels.push_back(std::move(c));
  }

  const McapMessage& message(const Record& r) {
    Fields fl(f_, name_, r.content, r.end, "Message");
    McapMessage m;
    m.channel_id = fl.u16("channel_id");
    m.sequence = fl.u32("sequence");
    m.log_time_ns = fl.u64("log_time");
    m.publish_time_ns = fl.u64("publish_time");
    m.data = fl.bytes(fl.remaining(), "data");
    if (out_.channel(m.channel_id) == nullptr) {
      fail(name_, r.offset, fmt::format("Message on channel {}, not defined before it", m.channel_id));
    }
    ++counts_[m.channel_id];
    out_.messages.push_back(std::move(m));
    return out_.messages.back();
  }

  void chunk(const Record& r) {
    Fields fl(f_, name_, r.content, r.end, "Chunk");
    ChunkInfo ci;
    ci.offset = r.offset;
    ci.length = r.end - r.offset;
    ci.start_ns = fl.u64("message_start_time");
    ci.end_ns = fl.u64("message_end_time");
    const std::uint64_t uncompressed_size = fl.u64("uncompressed_size");
    const std::uint32_t crc = fl.u32("uncompressed_crc");
    const std::string compression(fl.prefixed("compression"));
    if (!compression.empty() && compression != "zstd") {
      fail(
          name_, r.offset,
          fmt::format("Chunk compressed with '{}': only uncompressed and zstd chunks are read", compression));
    }
    std::uint64_t records_at = fl.pos() + 8;
    std::string_view records = fl.bytes(fl.u64("records length"), "records");
    if (fl.remaining() != 0) fail(name_, fl.pos(), "Chunk record: bytes after its records");
    out_.chunks.push_back({compression, records.size(), uncompressed_size});
    // A compressed chunk's records are parsed from their decompressed copy: offsets (the
    // MessageIndex's, the errors') then count within it, as the spec's message offsets do.
    std::string decompressed;
    const std::string_view file = f_;
    struct Restore {
      Parser& p;
      std::string_view file;
      ~Restore() {
        p.f_ = file;
        p.name_ = p.file_name_;
      }
    } restore{*this, file};
    if (compression == "zstd") {
      decompressed = zstd_decompress(records, uncompressed_size,
                                     fmt::format("{}: byte {}: zstd Chunk", name_, r.offset));
      f_ = decompressed;
      name_ = fmt::format("{} (zstd chunk at byte {}, decompressed)", file_name_, r.offset);
      records = f_;
      records_at = 0;
    }
    if (uncompressed_size != records.size()) {
      fail(name_, r.offset,
           fmt::format("Chunk uncompressed_size {} differs from its {} bytes of records", uncompressed_size,
                       records.size()));
    }
    if (crc != 0 && crc32(records) != crc) {
      fail(name_, r.offset,
           fmt::format("Chunk CRC mismatch (stored 0x{:08x}, computed 0x{:08x}): the records are corrupt",
                       crc, crc32(records)));
    }
    ci.records_size = records.size();
    ci.stored_size = out_.chunks.back().compressed_size;
    ci.compression = compression;
    const std::uint64_t end = records_at + records.size();
    std::optional<std::uint64_t> lo, hi;
    for (std::uint64_t at = records_at; at < end;) {
      const Record in = frame(at, end, "chunk");
      switch (static_cast<Op>(in.op)) {
        case Op::kSchema:
          define_schema(in);
          break;
        case Op::kChannel:
          define_channel(in);
          break;
        case Op::kMessage: {
          const McapMessage& m = message(in);
          if (m.log_time_ns < ci.start_ns || m.log_time_ns > ci.end_ns) {
            fail(name_, in.offset,
                 fmt::format("Message log time {} ns outside its chunk's range [{}, {}]", m.log_time_ns,
                             ci.start_ns, ci.end_ns));
          }
          lo = std::min(lo.value_or(m.log_time_ns), m.log_time_ns);
          hi = std::max(hi.value_or(m.log_time_ns), m.log_time_ns);
          ci.messages[m.channel_id].emplace_back(m.log_time_ns, at - records_at);
          break;
        }
        default:
          fail(name_, at, fmt::format("{} record not allowed inside a chunk", op_name(in.op)));
      }
      at = in.end;
    }
    if (lo && (*lo != ci.start_ns || *hi != ci.end_ns)) {
      fail(name_, r.offset,
           fmt::format("Chunk time range [{}, {}] is not its messages' [{}, {}]", ci.start_ns, ci.end_ns, *lo,
                       *hi));
    }
    for (auto& [id, entries] : ci.messages) std::stable_sort(entries.begin(), entries.end());
    chunks_.push_back(std::move(ci));
  }

  void message_index(const Record& r, ChunkInfo& ci) {
    Fields fl(f_, name_, r.content, r.end, "MessageIndex");
    const std::uint16_t id = fl.u16("channel_id");
    const std::uint64_t arr_at = fl.pos() + 4;
    const std::string_view arr = fl.prefixed("records");
    if (arr.size() % 16 != 0)
      fail(name_, arr_at, "MessageIndex records are not (u64 time, u64 offset) pairs");
    Fields a(f_, name_, arr_at, arr_at + arr.size(), "MessageIndex");
    std::vector<std::pair<std::uint64_t, std::uint64_t>> entries;
    while (a.remaining() > 0) {
      const std::uint64_t t = a.u64("log_time");
      entries.emplace_back(t, a.u64("offset"));
    }
    std::stable_sort(entries.begin(), entries.end());
    if (ci.index_offsets.count(id) != 0)
      fail(name_, r.offset, fmt::format("second MessageIndex for channel {}", id));
    const auto it = ci.messages.find(id);
    const auto& expected = it == ci.messages.end() ? decltype(it->second){} : it->second;
    if (entries != expected) {
      fail(name_, r.offset,
           fmt::format("MessageIndex of channel {} lists {} messages that differ from its chunk's {} (chunk "
                       "at byte {})",
                       id, entries.size(), expected.size(), ci.offset));
    }
    ci.index_offsets[id] = r.offset;
    if (ci.index_start == 0) ci.index_start = r.offset;
    ci.index_end = r.end;
  }

  // The data section, from the Header to DataEnd. Returns the offset just past DataEnd.
  std::uint64_t read_data() {
    std::uint64_t at = 8;
    const Record h = frame(at, footer_, "data section");
    if (h.op != static_cast<std::uint8_t>(Op::kHeader)) {
      fail(name_, at, fmt::format("expected the Header record after the magic, found {}", op_name(h.op)));
    }
    {
      Fields fl(f_, name_, h.content, h.end, "Header");
      out_.profile = fl.prefixed("profile");
      out_.library = fl.prefixed("library");
    }
    at = h.end;
    bool after_chunk = false;  // MessageIndex records may follow a chunk only
    while (true) {
      const Record r = frame(at, footer_, "data section");
      const auto op = static_cast<Op>(r.op);
      if (op != Op::kMessageIndex) after_chunk = false;
      switch (op) {
        case Op::kSchema:
          define_schema(r);
          break;
        case Op::kChannel:
          define_channel(r);
          break;
        case Op::kMessage:
          message(r);
          break;
        case Op::kChunk:
          chunk(r);
          after_chunk = true;
          break;
        case Op::kMessageIndex:
          if (!after_chunk) fail(name_, at, "MessageIndex record that does not follow a chunk");
          message_index(r, chunks_.back());
          break;
        case Op::kAttachment:
          attachment(r);
          ++attachments_;
          break;
        case Op::kMetadata:
          metadata(r);
          ++metadata_;
          break;
        case Op::kDataEnd: {
          Fields fl(f_, name_, r.content, r.end, "DataEnd");
          const std::uint32_t crc = fl.u32("data_section_crc");
          if (crc != 0 && crc32(f_.substr(0, at)) != crc) {
            fail(name_, at,
                 fmt::format("data section CRC mismatch (stored 0x{:08x}, computed 0x{:08x})", crc,
                             crc32(f_.substr(0, at))));
          }
          for (const auto& ci : chunks_) {
            for (const auto& [id, entries] : ci.messages) {
              if (ci.index_offsets.count(id) == 0) {
                fail(name_, ci.offset, fmt::format("chunk has no MessageIndex for channel {}", id));
              }
            }
          }
          return r.end;
        }
        case Op::kHeader:
        case Op::kFooter:
        case Op::kChunkIndex:
        case Op::kAttachmentIndex:
        case Op::kStatistics:
        case Op::kMetadataIndex:
        case Op::kSummaryOffset:
          fail(name_, at, fmt::format("{} record in the data section (no DataEnd before it)", op_name(r.op)));
        default:
          break;  // unknown opcodes are skipped, as the spec asks
      }
      at = r.end;
    }
  }

  void read_summary(std::uint64_t data_end) {
    const std::uint64_t offsets_end = footer_;
    if (summary_start_ == 0) {
      const std::uint64_t next = summary_offset_start_ ? summary_offset_start_ : footer_;
      if (data_end != next) fail(name_, data_end, "bytes between DataEnd and the footer, and no summary");
    } else if (summary_start_ != data_end) {
      fail(name_, footer_,
           fmt::format("footer's summary_start {} is not where the data section ends ({})", summary_start_,
                       data_end));
    }
    const std::uint64_t summary_end = summary_offset_start_ ? summary_offset_start_ : footer_;
    if (summary_offset_start_ && (summary_offset_start_ < data_end || summary_offset_start_ > footer_)) {
      fail(name_, footer_,
           fmt::format("footer's summary_offset_start {} is outside [{}, {}]", summary_offset_start_,
                       data_end, footer_));
    }
    if (summary_crc_ != 0) {
      const std::uint64_t from =
          summary_start_ ? summary_start_ : (summary_offset_start_ ? summary_offset_start_ : footer_);
      const std::uint32_t crc = crc32(f_.substr(from, footer_ + 25 - from));
      if (crc != summary_crc_) {
        fail(name_, footer_,
             fmt::format("summary CRC mismatch (stored 0x{:08x}, computed 0x{:08x})", summary_crc_, crc));
      }
    }
    out_.chunk_count = chunks_.size();
    if (summary_start_ == 0) return;
    out_.has_summary = true;

    std::vector<std::uint16_t> schemas, channels;
    std::size_t chunk_indexes = 0;
    for (std::uint64_t at = summary_start_; at < summary_end;) {
      const Record r = frame(at, summary_end, "summary");
      switch (static_cast<Op>(r.op)) {
        case Op::kSchema: {
          const McapSchema s = parse_schema(r);
          const auto* d = out_.schema(s.id);
          if (!d || d->name != s.name || d->encoding != s.encoding || d->data != s.data) {
            fail(name_, at, fmt::format("summary Schema {} differs from the data section's", s.id));
          }
          schemas.push_back(s.id);
          break;
        }
        case Op::kChannel: {
          const McapChannel c = parse_channel(r);
          const auto* d = out_.channel(c.id);
          if (!d || d->schema_id != c.schema_id || d->topic != c.topic ||
              d->message_encoding != c.message_encoding || d->metadata != c.metadata) {
            fail(name_, at, fmt::format("summary Channel {} differs from the data section's", c.id));
          }
          channels.push_back(c.id);
          break;
        }
        case Op::kStatistics:
          if (out_.has_statistics) fail(name_, at, "second Statistics record");
          statistics(r);
          break;
        case Op::kChunkIndex:
          if (chunk_indexes >= chunks_.size())
            fail(name_, at, "ChunkIndex without a chunk in the data section");
          chunk_index(r, chunks_[chunk_indexes++]);
          break;
        case Op::kAttachmentIndex:
          attachment_index(r);
          break;
        case Op::kMetadataIndex:
          metadata_index(r);
          break;
        case Op::kHeader:
        case Op::kFooter:
        case Op::kMessage:
        case Op::kChunk:
        case Op::kMessageIndex:
        case Op::kAttachment:
        case Op::kMetadata:
        case Op::kSummaryOffset:
        case Op::kDataEnd:
          fail(name_, at, fmt::format("{} record not allowed in the summary", op_name(r.op)));
        default:
          break;
      }
      at = r.end;
    }
    if (chunk_indexes != chunks_.size()) {
      fail(name_, summary_start_,
           fmt::format("summary has {} ChunkIndex records for {} chunks", chunk_indexes, chunks_.size()));
    }
    if (attachment_indexes_ != attachment_records_.size() || metadata_indexes_ != metadata_records_.size()) {
      fail(name_, summary_start_,
           fmt::format("summary indexes {} of {} attachments and {} of {} metadata records",
                       attachment_indexes_, attachment_records_.size(), metadata_indexes_,
                       metadata_records_.size()));
    }
    if (schemas.size() != out_.schemas.size() || channels.size() != out_.channels.size()) {
      fail(name_, summary_start_,
           fmt::format("summary repeats {} of {} schemas and {} of {} channels (all are needed to seek)",
                       schemas.size(), out_.schemas.size(), channels.size(), out_.channels.size()));
    }

    // Summary offsets: each group covers whole records of its opcode inside the summary.
    for (std::uint64_t at = summary_offset_start_ ? summary_offset_start_ : offsets_end; at < offsets_end;) {
      const Record r = frame(at, offsets_end, "summary offset section");
      if (r.op != static_cast<std::uint8_t>(Op::kSummaryOffset)) {
        fail(name_, at, fmt::format("{} record in the summary offset section", op_name(r.op)));
      }
      Fields fl(f_, name_, r.content, r.end, "SummaryOffset");
      const std::uint8_t op = fl.u8("group_opcode");
      const std::uint64_t start = fl.u64("group_start");
      const std::uint64_t length = fl.u64("group_length");
      if (start < summary_start_ || start > summary_end || length > summary_end - start) {
        fail(name_, at,
             fmt::format("SummaryOffset group [{}, +{}) lies outside the summary [{}, {})", start, length,
                         summary_start_, summary_end));
      }
      for (std::uint64_t g = start; g < start + length;) {
        const Record in = frame(g, start + length, "summary offset group");
        if (in.op != op) {
          fail(name_, g,
               fmt::format("{} record in the SummaryOffset group of {}", op_name(in.op), op_name(op)));
        }
        g = in.end;
      }
      at = r.end;
    }
  }

  void metadata(const Record& r) {
    Fields fl(f_, name_, r.content, r.end, "Metadata");
    McapMetadata m;
    m.name = fl.prefixed("name");
    const std::uint64_t map_at = fl.pos() + 4;
    const std::string_view map = fl.prefixed("metadata");
    Fields e(f_, name_, map_at, map_at + map.size(), "Metadata map");
    while (e.remaining() > 0) {
      std::string k(e.prefixed("metadata key"));
      std::string v(e.prefixed("metadata value"));
      m.entries.emplace_back(std::move(k), std::move(v));
    }
    metadata_records_.push_back({r.offset, r.end - r.offset, m.name});
    out_.metadata.push_back(std::move(m));
  }

  void attachment(const Record& r) {
    Fields fl(f_, name_, r.content, r.end, "Attachment");
    McapAttachment a;
    a.log_time_ns = fl.u64("log_time");
    a.create_time_ns = fl.u64("create_time");
    a.name = fl.prefixed("name");
    a.media_type = fl.prefixed("media_type");
    a.data = fl.bytes(fl.u64("data length"), "data");
    const std::uint64_t crc_at = fl.pos();
    const std::uint32_t crc = fl.u32("crc");
    if (fl.remaining() != 0) fail(name_, fl.pos(), "Attachment record: bytes after its crc");
    const std::uint32_t actual = crc32(f_.substr(r.content, crc_at - r.content));
    if (crc != 0 && crc != actual) {
      fail(name_, r.offset,
           fmt::format("Attachment '{}' CRC mismatch (stored 0x{:08x}, computed 0x{:08x})", a.name, crc,
                       actual));
    }
    attachment_records_.push_back({r.offset, r.end - r.offset, a.name});
    out_.attachments.push_back(std::move(a));
  }

  // An index record of the summary must point at the next Attachment/Metadata record, by name.
  void check_index(const Record& r, const char* what, std::uint64_t offset, std::uint64_t length,
                   const std::string& name, const std::vector<IndexTarget>& targets, std::size_t& n) {
    if (n >= targets.size())
      fail(name_, r.offset, fmt::format("{} without its record in the data section", what));
    const IndexTarget& t = targets[n++];
    if (offset != t.offset || length != t.length || name != t.name) {
      fail(name_, r.offset,
           fmt::format("{} ('{}' at byte {}, {} bytes) does not match the record ('{}' at byte {}, {} bytes)",
                       what, name, offset, length, t.name, t.offset, t.length));
    }
  }

  void attachment_index(const Record& r) {
    Fields fl(f_, name_, r.content, r.end, "AttachmentIndex");
    const std::uint64_t offset = fl.u64("offset"), length = fl.u64("length");
    fl.u64("log_time");
    fl.u64("create_time");
    fl.u64("data_size");
    const std::string name(fl.prefixed("name"));
    fl.prefixed("media_type");
    check_index(r, "AttachmentIndex", offset, length, name, attachment_records_, attachment_indexes_);
  }

  void metadata_index(const Record& r) {
    Fields fl(f_, name_, r.content, r.end, "MetadataIndex");
    const std::uint64_t offset = fl.u64("offset"), length = fl.u64("length");
    const std::string name(fl.prefixed("name"));
    check_index(r, "MetadataIndex", offset, length, name, metadata_records_, metadata_indexes_);
  }

  void statistics(const Record& r) {
    Fields fl(f_, name_, r.content, r.end, "Statistics");
    McapStatistics& s = out_.statistics;
    s.message_count = fl.u64("message_count");
    s.schema_count = fl.u16("schema_count");
    s.channel_count = fl.u32("channel_count");
    s.attachment_count = fl.u32("attachment_count");
    s.metadata_count = fl.u32("metadata_count");
    s.chunk_count = fl.u32("chunk_count");
    s.message_start_time_ns = fl.u64("message_start_time");
    s.message_end_time_ns = fl.u64("message_end_time");
    const std::uint64_t map_at = fl.pos() + 4;
    const std::string_view map = fl.prefixed("channel_message_counts");
    Fields m(f_, name_, map_at, map_at + map.size(), "Statistics channel_message_counts");
    while (m.remaining() > 0) {
      const std::uint16_t id = m.u16("channel id");
      s.channel_message_counts[id] = m.u64("count");
    }
    out_.has_statistics = true;

    std::uint64_t lo = 0, hi = 0;
    for (std::size_t i = 0; i < out_.messages.size(); ++i) {
      const std::uint64_t t = out_.messages[i].log_time_ns;
      lo = i ? std::min(lo, t) : t;
      hi = i ? std::max(hi, t) : t;
    }
    const auto check = [&](bool ok, const char* field, std::uint64_t stored, std::uint64_t actual) {
      if (!ok)
        fail(name_, r.offset, fmt::format("Statistics {} is {}, the data has {}", field, stored, actual));
    };
    check(s.message_count == out_.messages.size(), "message_count", s.message_count, out_.messages.size());
    check(s.schema_count == out_.schemas.size(), "schema_count", s.schema_count, out_.schemas.size());
    check(s.channel_count == out_.channels.size(), "channel_count", s.channel_count, out_.channels.size());
    check(s.attachment_count == attachments_, "attachment_count", s.attachment_count, attachments_);
    check(s.metadata_count == metadata_, "metadata_count", s.metadata_count, metadata_);
    check(s.chunk_count == chunks_.size(), "chunk_count", s.chunk_count, chunks_.size());
    check(s.message_start_time_ns == lo, "message_start_time", s.message_start_time_ns, lo);
    check(s.message_end_time_ns == hi, "message_end_time", s.message_end_time_ns, hi);
    for (const auto& c : out_.channels) {
      const auto it = s.channel_message_counts.find(c.id);
      const std::uint64_t stored = it == s.channel_message_counts.end() ? 0 : it->second;
      const std::uint64_t actual = counts_.count(c.id) ? counts_.at(c.id) : 0;
      if (stored != actual) {
        fail(name_, r.offset,
             fmt::format("Statistics count of channel {} is {}, the data has {}", c.id, stored, actual));
      }
    }
  }

  void chunk_index(const Record& r, const ChunkInfo& ci) {
    Fields fl(f_, name_, r.content, r.end, "ChunkIndex");
    const std::uint64_t start = fl.u64("message_start_time");
    const std::uint64_t end = fl.u64("message_end_time");
    const std::uint64_t offset = fl.u64("chunk_start_offset");
    const std::uint64_t length = fl.u64("chunk_length");
    const std::uint64_t map_at = fl.pos() + 4;
    const std::string_view map = fl.prefixed("message_index_offsets");
    std::map<std::uint16_t, std::uint64_t> offsets;
    Fields m(f_, name_, map_at, map_at + map.size(), "ChunkIndex message_index_offsets");
    while (m.remaining() > 0) {
      const std::uint16_t id = m.u16("channel id");
      offsets[id] = m.u64("offset");
    }
    const std::uint64_t index_length = fl.u64("message_index_length");
    const std::string_view compression = fl.prefixed("compression");
    const std::uint64_t compressed = fl.u64("compressed_size");
    const std::uint64_t uncompressed = fl.u64("uncompressed_size");
    const auto check = [&](bool ok, const char* field, std::uint64_t stored, std::uint64_t actual) {
      if (!ok) {
        fail(name_, r.offset,
             fmt::format("ChunkIndex {} is {}, the chunk at byte {} has {}", field, stored, ci.offset,
                         actual));
      }
    };
    check(offset == ci.offset, "chunk_start_offset", offset, ci.offset);
    check(length == ci.length, "chunk_length", length, ci.length);
    check(start == ci.start_ns, "message_start_time", start, ci.start_ns);
    check(end == ci.end_ns, "message_end_time", end, ci.end_ns);
    check(compressed == ci.stored_size, "compressed_size", compressed, ci.stored_size);
    check(uncompressed == ci.records_size, "uncompressed_size", uncompressed, ci.records_size);
    check(index_length == ci.index_end - ci.index_start, "message_index_length", index_length,
          ci.index_end - ci.index_start);
    if (compression != ci.compression) {
      fail(name_, r.offset,
           fmt::format("ChunkIndex names compression '{}', the chunk at byte {} has '{}'", compression,
                       ci.offset, ci.compression));
    }
    if (offsets != ci.index_offsets) {
      fail(name_, r.offset,
           fmt::format(
               "ChunkIndex message_index_offsets do not point at the chunk's MessageIndex records (chunk at "
               "byte {})",
               ci.offset));
    }
  }

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

}  // namespace

McapContents parse_mcap(std::string_view bytes, const std::string& name) { return Parser(bytes, name).run(); }

McapContents read_mcap(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InvalidInput(file.string(), 0, "cannot open");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InvalidInput(file.string(), 0, "read failed");
  return parse_mcap(bytes, file.string());
}

}  // namespace mc
