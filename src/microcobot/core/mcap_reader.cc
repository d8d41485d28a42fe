#include "microcobot/core/mcap_reader.h"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <optional>
#include <tuple>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/core/mcap_parser.h"
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

namespace mcap_detail {

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

McapContents Parser::run() {
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

// The record at `at`, which must end by `limit`.
Record Parser::frame(std::uint64_t at, std::uint64_t limit, const char* where) {
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
         fmt::format("{} record of {} bytes runs past the end of the {} ({} bytes left)", op_name(r.op), len,
                     where, limit - r.content));
  }
  r.end = r.content + len;
  return r;
}

McapSchema Parser::parse_schema(const Record& r) {
  Fields fl(f_, name_, r.content, r.end, "Schema");
  McapSchema s;
  s.id = fl.u16("id");
  s.name = fl.prefixed("name");
  s.encoding = fl.prefixed("encoding");
  s.data = fl.prefixed("data");
  if (s.id == 0) fail(name_, r.offset, "Schema record with id 0 (reserved for \"no schema\")");
  return s;
}

McapChannel Parser::parse_channel(const Record& r) {
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

void Parser::define_schema(const Record& r) {
  McapSchema s = parse_schema(r);
  if (const auto* old = out_.schema(s.id)) {
    if (old->name != s.name || old->encoding != s.encoding || old->data != s.data) {
      fail(name_, r.offset, fmt::format("Schema {} redefined differently", s.id));
    }
    return;
  }
  out_.schemas.push_back(std::move(s));
}

void Parser::define_channel(const Record& r) {
  McapChannel c = parse_channel(r);
  if (c.schema_id != 0 && out_.schema(c.schema_id) == nullptr) {
    fail(name_, r.offset,
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

const McapMessage& Parser::message(const Record& r) {
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

void Parser::chunk(const Record& r) {
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
    fail(name_, r.offset,
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
    decompressed =
        zstd_decompress(records, uncompressed_size, fmt::format("{}: byte {}: zstd Chunk", name_, r.offset));
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
         fmt::format("Chunk CRC mismatch (stored 0x{:08x}, computed 0x{:08x}): the records are corrupt", crc,
                     crc32(records)));
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

void Parser::message_index(const Record& r, ChunkInfo& ci) {
  Fields fl(f_, name_, r.content, r.end, "MessageIndex");
  const std::uint16_t id = fl.u16("channel_id");
  const std::uint64_t arr_at = fl.pos() + 4;
  const std::string_view arr = fl.prefixed("records");
  if (arr.size() % 16 != 0) fail(name_, arr_at, "MessageIndex records are not (u64 time, u64 offset) pairs");
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
std::uint64_t Parser::read_header() {
  const Record h = frame(8, footer_, "data section");
  if (h.op != static_cast<std::uint8_t>(Op::kHeader)) {
    fail(name_, 8, fmt::format("expected the Header record after the magic, found {}", op_name(h.op)));
  }
  Fields fl(f_, name_, h.content, h.end, "Header");
  out_.profile = fl.prefixed("profile");
  out_.library = fl.prefixed("library");
  return h.end;
}

std::uint64_t Parser::read_data() {
  std::uint64_t at = read_header();
  bool after_chunk = false;  // MessageIndex records may follow a chunk only
  while (true) {
    const Record r = frame(at, footer_, "data section");
    const auto op = static_cast<Op>(r.op);
    if (op != Op::kMessageIndex) after_chunk = false;
    if (content_record(r)) {
      after_chunk = op == Op::kChunk;
      at = r.end;
      continue;
    }
    switch (op) {
      case Op::kMessageIndex:
        if (!after_chunk) fail(name_, at, "MessageIndex record that does not follow a chunk");
        message_index(r, chunks_.back());
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
      default:
        summary_only(r);  // fails on a summary record; unknown opcodes are skipped, as the spec asks
    }
    at = r.end;
  }
}

bool Parser::content_record(const Record& r) {
  switch (static_cast<Op>(r.op)) {
    case Op::kSchema:
      define_schema(r);
      return true;
    case Op::kChannel:
      define_channel(r);
      return true;
    case Op::kMessage:
      message(r);
      return true;
    case Op::kChunk:
      chunk(r);
      return true;
    case Op::kAttachment:
      attachment(r);
      ++attachments_;
      return true;
    case Op::kMetadata:
      metadata(r);
      ++metadata_;
      return true;
    default:
      return false;
  }
}

void Parser::summary_only(const Record& r) {
  switch (static_cast<Op>(r.op)) {
    case Op::kHeader:
    case Op::kFooter:
    case Op::kChunkIndex:
    case Op::kAttachmentIndex:
    case Op::kStatistics:
    case Op::kMetadataIndex:
    case Op::kSummaryOffset:
      fail(name_, r.offset,
           fmt::format("{} record in the data section (no DataEnd before it)", op_name(r.op)));
    default:
      break;
  }
}

void Parser::metadata(const Record& r) {
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

void Parser::attachment(const Record& r) {
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

}  // namespace mcap_detail

McapContents parse_mcap(std::string_view bytes, const std::string& name) {
  return mcap_detail::Parser(bytes, name).run();
}

McapContents read_mcap(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InvalidInput(file.string(), 0, "cannot open");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InvalidInput(file.string(), 0, "read failed");
  return parse_mcap(bytes, file.string());
}

}  // namespace mc
