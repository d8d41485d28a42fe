#include "microcobot/core/mcap_writer.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <tuple>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/core/zstd.h"

namespace mc {

namespace {

// zlib's crc32 would do, but zlib is not among the project's dependencies; a byte-wise table
// (1 KiB, built once) runs at several hundred MB/s, far more than a recording needs.
constexpr std::array<std::uint32_t, 256> make_crc_table() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t n = 0; n < 256; ++n) {
    std::uint32_t c = n;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[n] = c;
  }
  return t;
}
constexpr auto kCrcTable = make_crc_table();

// Little-endian fields (spec, "Serialization").
void put_u8(std::string& s, std::uint8_t v) { s.push_back(static_cast<char>(v)); }
void put_u16(std::string& s, std::uint16_t v) {
  for (int i = 0; i < 2; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xFFu));
}
void put_u32(std::string& s, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xFFu));
}
void put_u64(std::string& s, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xFFu));
}
// String and Bytes: uint32 length prefix, then the bytes.
void put_str(std::string& s, std::string_view v) {
  put_u32(s, static_cast<std::uint32_t>(v.size()));
  s.append(v);
}

constexpr std::size_t kRecordPrefix = 1 + 8;           // opcode, content length
constexpr std::size_t kMessagePrefix = 2 + 4 + 8 + 8;  // channel, sequence, log and publish time
constexpr std::size_t kIoBuffer = std::size_t{1} << 20;

}  // namespace

std::uint32_t crc32(std::string_view bytes, std::uint32_t previous) {
  std::uint32_t c = previous ^ 0xFFFFFFFFu;
  for (const char ch : bytes) c = kCrcTable[(c ^ static_cast<std::uint8_t>(ch)) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

McapWriter::McapWriter(std::filesystem::path path, std::size_t chunk_target_bytes,
                       McapCompression compression)
    : path_(std::move(path)),
      file_(path_),
      chunk_target_(std::max<std::size_t>(chunk_target_bytes, 1)),
      compression_(compression) {
  if (compression_.zstd)
    require(compression_.zstd_level >= 1 && compression_.zstd_level <= 19, "zstd_level",
            "must be within [1, 19]", compression_.zstd_level);
  out_.reserve(kIoBuffer);
  chunk_.reserve(std::min(chunk_target_, std::size_t{64} << 20) + 4096);
  put(kMcapMagic);
  scratch_.clear();
  put_str(scratch_, "");            // profile
  put_str(scratch_, "microcobot");  // library
  put_record(McapOpcode::kHeader, scratch_);
}

McapWriter::~McapWriter() = default;  // unclosed: the staged file removes its temporary

void McapWriter::flush_buffer() {
  try {
    file_.write(out_);  // discards the file when it fails
  } catch (...) {
    closed_ = true;
    throw;
  }
  flushed_ += out_.size();
  out_.clear();
}

void McapWriter::put(std::string_view bytes) {
  if (in_data_) data_crc_ = crc32(bytes, data_crc_);
  if (out_.size() + bytes.size() > kIoBuffer) flush_buffer();
  out_.append(bytes);
  if (out_.size() >= kIoBuffer) flush_buffer();
}

void McapWriter::put_record(McapOpcode op, std::string_view content) {
  std::string prefix;
  prefix.reserve(kRecordPrefix);
  put_u8(prefix, static_cast<std::uint8_t>(op));
  put_u64(prefix, content.size());
  put(prefix);
  put(content);
}

std::uint16_t McapWriter::add_schema(std::string_view name, std::string_view encoding,
                                     std::string_view data) {
  if (closed_) throw InvalidInput(path_.string(), 0, "add_schema after close");
  if (schemas_.size() >= 0xFFFFu) throw InvalidInput(path_.string(), 0, "too many schemas (65535 at most)");
  const auto id = static_cast<std::uint16_t>(schemas_.size() + 1);
  std::string rec;
  put_u16(rec, id);
  put_str(rec, name);
  put_str(rec, encoding);
  put_str(rec, data);
  put_record(McapOpcode::kSchema, rec);
  schemas_.push_back(std::move(rec));
  return id;
}

std::uint16_t McapWriter::add_channel(std::uint16_t schema_id, std::string_view topic,
                                      std::string_view message_encoding,
                                      const std::vector<std::pair<std::string, std::string>>& metadata) {
  if (closed_) throw InvalidInput(path_.string(), 0, "add_channel after close");
  if (schema_id > schemas_.size()) {
    throw InvalidInput(
        path_.string(), 0,
        fmt::format("channel '{}': unknown schema id {} ({} schemas)", topic, schema_id, schemas_.size()));
  }
  if (channels_.size() >= 0xFFFFu) throw InvalidInput(path_.string(), 0, "too many channels (65535 at most)");
  const auto id = static_cast<std::uint16_t>(channels_.size() + 1);
  ChannelState ch;
  put_u16(ch.record, id);
  put_u16(ch.record, schema_id);
  put_str(ch.record, topic);
  put_str(ch.record, message_encoding);
  std::string map;
  for (const auto& [k, v] : metadata) {
    put_str(map, k);
    put_str(map, v);
  }
  put_str(ch.record, map);  // Map<string,string>: uint32 byte length, then the pairs
  put_record(McapOpcode::kChannel, ch.record);
  channels_.push_back(std::move(ch));
  return id;
}

void McapWriter::add_metadata(std::string_view name,
                              const std::vector<std::pair<std::string, std::string>>& entries) {
  if (closed_) throw InvalidInput(path_.string(), 0, "add_metadata after close");
  std::string rec;
  put_str(rec, name);
  std::string map;
  for (const auto& [k, v] : entries) {
    put_str(map, k);
    put_str(map, v);
  }
  put_str(rec, map);
  // MetadataIndex: offset, length (of the whole record), name.
  std::string index;
  put_u64(index, position());
  put_u64(index, kRecordPrefix + rec.size());
  put_str(index, name);
  put_record(McapOpcode::kMetadata, rec);
  indexes_.push_back({McapOpcode::kMetadataIndex, std::move(index)});
  ++metadata_count_;
}

void McapWriter::add_attachment(std::string_view name, std::string_view media_type, std::string_view data,
                                std::uint64_t log_time_ns, std::uint64_t create_time_ns) {
  if (closed_) throw InvalidInput(path_.string(), 0, "add_attachment after close");
  std::string rec;
  put_u64(rec, log_time_ns);
  put_u64(rec, create_time_ns);
  put_str(rec, name);
  put_str(rec, media_type);
  put_u64(rec, data.size());  // Bytes with a uint64 length, unlike the other records' uint32
  rec.append(data);
  put_u32(rec, crc32(rec));  // the CRC of every field before it
  // AttachmentIndex: offset, length, log time, create time, data size, name, media type.
  std::string index;
  put_u64(index, position());
  put_u64(index, kRecordPrefix + rec.size());
  put_u64(index, log_time_ns);
  put_u64(index, create_time_ns);
  put_u64(index, data.size());
  put_str(index, name);
  put_str(index, media_type);
  put_record(McapOpcode::kAttachment, rec);
  indexes_.push_back({McapOpcode::kAttachmentIndex, std::move(index)});
  ++attachment_count_;
}

void McapWriter::write(std::uint16_t channel_id, std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
                       std::span<const std::byte> payload) {
  write(channel_id, log_time_ns, publish_time_ns,
        std::string_view(reinterpret_cast<const char*>(payload.data()), payload.size()));
}

void McapWriter::write(std::uint16_t channel_id, std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
                       std::string_view payload) {
  if (closed_) throw InvalidInput(path_.string(), 0, "write after close");
  if (channel_id == 0 || channel_id > channels_.size()) {
    throw InvalidInput(
        path_.string(), 0,
        fmt::format("message on unknown channel id {} ({} channels)", channel_id, channels_.size()));
  }
  ChannelState& ch = channels_[channel_id - 1u];
  // A message a span or more after the open chunk's first: that chunk holds its span, and goes.
  if (chunk_span_ns_ != 0 && !chunk_.empty() && log_time_ns >= chunk_start_ns_ + chunk_span_ns_) {
    close_chunk();
    flush_buffer();
    take_checkpoint();
  }
  if (chunk_.empty()) {
    chunk_start_ns_ = chunk_end_ns_ = log_time_ns;
  } else {
    chunk_start_ns_ = std::min(chunk_start_ns_, log_time_ns);
    chunk_end_ns_ = std::max(chunk_end_ns_, log_time_ns);
  }
  if (message_count_ == 0) {
    start_ns_ = end_ns_ = log_time_ns;
  } else {
    start_ns_ = std::min(start_ns_, log_time_ns);
    end_ns_ = std::max(end_ns_, log_time_ns);
  }
  ch.index.emplace_back(log_time_ns, chunk_.size());  // offset within the chunk's records
  put_u8(chunk_, static_cast<std::uint8_t>(McapOpcode::kMessage));
  put_u64(chunk_, kMessagePrefix + payload.size());
  put_u16(chunk_, channel_id);
  put_u32(chunk_, static_cast<std::uint32_t>(ch.count));  // sequence: per channel, wraps
  put_u64(chunk_, log_time_ns);
  put_u64(chunk_, publish_time_ns);
  chunk_.append(payload);
  ++ch.count;
  ++message_count_;
  if (chunk_.size() >= chunk_target_) {
    close_chunk();
    if (chunk_span_ns_ != 0) {
      flush_buffer();
      take_checkpoint();
    }
  }
}

void McapWriter::set_chunk_max_span_ns(std::uint64_t span_ns) {
  chunk_span_ns_ = span_ns;
  if (span_ns == 0) return;
  close_chunk();
  flush_buffer();  // a file that cannot take its header is discarded, as any
  file_.keep_on_failure();
  take_checkpoint();
}

void McapWriter::take_checkpoint() {
  Checkpoint& c = checkpoint_;
  c.position = flushed_;
  c.data_crc = data_crc_;
  c.schemas = schemas_.size();
  c.channels = channels_.size();
  c.chunks = chunk_indexes_.mark();
  c.indexes = indexes_.size();
  c.attachments = attachment_count_;
  c.metadata = metadata_count_;
  c.messages = message_count_;
  c.start_ns = start_ns_;
  c.end_ns = end_ns_;
  c.records_bytes = records_bytes_;
  c.stored_bytes = stored_bytes_;
  c.channel_counts.resize(channels_.size());
  for (std::size_t i = 0; i < channels_.size(); ++i) c.channel_counts[i] = channels_[i].count;
}

std::uint64_t McapWriter::close_at_last_chunk() {
  if (chunk_span_ns_ == 0) throw InvalidInput(path_.string(), 0, "close_at_last_chunk needs a chunk span");
  const Checkpoint& c = checkpoint_;
  file_.truncate(c.position);
  flushed_ = c.position;
  out_.clear();
  chunk_.clear();
  data_crc_ = c.data_crc;
  schemas_.resize(c.schemas);
  channels_.resize(c.channels);
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    channels_[i].count = c.channel_counts[i];
    channels_[i].index.clear();
  }
  chunk_indexes_.truncate(c.chunks);
  indexes_.resize(c.indexes);
  attachment_count_ = c.attachments;
  metadata_count_ = c.metadata;
  message_count_ = c.messages;
  start_ns_ = c.start_ns;
  end_ns_ = c.end_ns;
  records_bytes_ = c.records_bytes;
  stored_bytes_ = c.stored_bytes;
  in_data_ = true;
  closed_ = false;
  close();
  return message_count_;
}

void McapWriter::close_chunk() {
  if (chunk_.empty()) return;
  const std::uint64_t chunk_offset = position();
  const std::uint64_t records_size = chunk_.size();
  // Chunk: start, end, uncompressed size, uncompressed CRC, compression, records (u64 length).
  // The CRC is of the records before compression (spec, "Chunk"): a reader checks what it
  // decompressed.
  const std::uint32_t crc = crc32(chunk_);
  std::string_view stored = chunk_;
  const std::string_view compression = compression_.zstd ? "zstd" : "";
  if (compression_.zstd) {
    zstd_compress(chunk_, compression_.zstd_level, compressed_);
    stored = compressed_;
  }
  const std::uint64_t stored_size = stored.size();
  scratch_.clear();
  put_u8(scratch_, static_cast<std::uint8_t>(McapOpcode::kChunk));
  const std::uint64_t content = 8 + 8 + 8 + 4 + 4 + compression.size() + 8 + stored.size();
  put_u64(scratch_, content);
  put_u64(scratch_, chunk_start_ns_);
  put_u64(scratch_, chunk_end_ns_);
  put_u64(scratch_, chunk_.size());
  put_u32(scratch_, crc);
  put_str(scratch_, compression);
  put_u64(scratch_, stored.size());
  put(scratch_);
  put(stored);
  records_bytes_ += chunk_.size();
  stored_bytes_ += stored.size();
  // One MessageIndex per channel present in the chunk, entries in log-time order; where each
  // starts goes into the ChunkIndex's message_index_offsets (channel id u16, offset u64).
  std::string& offsets = index_offsets_;
  offsets.clear();
  const std::uint64_t index_start = position();
  for (std::size_t c = 0; c < channels_.size(); ++c) {
    auto& index = channels_[c].index;
    if (index.empty()) continue;
    if (!std::is_sorted(index.begin(), index.end())) std::stable_sort(index.begin(), index.end());
    put_u16(offsets, static_cast<std::uint16_t>(c + 1));
    put_u64(offsets, position());
    scratch_.clear();
    put_u16(scratch_, static_cast<std::uint16_t>(c + 1));
    put_u32(scratch_, static_cast<std::uint32_t>(index.size() * 16));
    for (const auto& [t, off] : index) {
      put_u64(scratch_, t);
      put_u64(scratch_, off);
    }
    put_record(McapOpcode::kMessageIndex, scratch_);
    index.clear();
  }
  const std::uint64_t index_length = position() - index_start;
  // ChunkIndex (spec, "Chunk Index"): start, end, chunk offset and length, the message index
  // offsets, their length, compression, compressed and uncompressed sizes.
  scratch_.clear();
  put_u64(scratch_, chunk_start_ns_);
  put_u64(scratch_, chunk_end_ns_);
  put_u64(scratch_, chunk_offset);
  put_u64(scratch_, kRecordPrefix + content);
  put_str(scratch_, offsets);
  put_u64(scratch_, index_length);
  put_str(scratch_, compression);
  put_u64(scratch_, stored_size);
  put_u64(scratch_, records_size);
  std::string& record = chunk_index_record_;
  record.clear();
  put_u8(record, static_cast<std::uint8_t>(McapOpcode::kChunkIndex));
  put_u64(record, scratch_.size());
  record += scratch_;
  chunk_indexes_.append(record);
  chunk_.clear();
}

void McapWriter::ChunkIndexLog::append(std::string_view record) {
  if (blocks.empty() || blocks.back().size() + record.size() > kBlockBytes) {
    blocks.emplace_back();
    blocks.back().reserve(std::max(kBlockBytes, record.size()));
  }
  blocks.back() += record;
  ++count;
}

void McapWriter::ChunkIndexLog::truncate(const Mark& m) {
  blocks.resize(m.blocks);
  if (!blocks.empty()) blocks.back().resize(m.last_size);
  count = m.count;
}

std::size_t McapWriter::ChunkIndexLog::reserved() const {
  std::size_t n = blocks.capacity() * sizeof(std::string);
  for (const auto& b : blocks) n += b.capacity();
  return n;
}

void McapWriter::close() {
  if (closed_) return;
  close_chunk();
  // DataEnd carries the CRC of everything before it.
  const std::uint32_t data_crc = data_crc_;
  in_data_ = false;
  scratch_.clear();
  put_u32(scratch_, data_crc);
  put_record(McapOpcode::kDataEnd, scratch_);

  // The summary, in groups, each group listed in a SummaryOffset record.
  const std::uint64_t summary_start = position();
  std::string summary;
  std::vector<std::tuple<McapOpcode, std::uint64_t, std::uint64_t>> groups;  // opcode, start, length
  const auto add_record = [&](McapOpcode op, std::string_view content) {
    put_u8(summary, static_cast<std::uint8_t>(op));
    put_u64(summary, content.size());
    summary.append(content);
  };
  const auto group = [&](McapOpcode op, const auto& fill) {
    const std::size_t begin = summary.size();
    fill();
    if (summary.size() > begin) groups.emplace_back(op, summary_start + begin, summary.size() - begin);
  };
  group(McapOpcode::kSchema, [&] {
    for (const auto& s : schemas_) add_record(McapOpcode::kSchema, s);
  });
  group(McapOpcode::kChannel, [&] {
    for (const auto& c : channels_) add_record(McapOpcode::kChannel, c.record);
  });
  group(McapOpcode::kStatistics, [&] {
    std::string s;
    put_u64(s, message_count_);
    put_u16(s, static_cast<std::uint16_t>(schemas_.size()));
    put_u32(s, static_cast<std::uint32_t>(channels_.size()));
    put_u32(s, attachment_count_);
    put_u32(s, metadata_count_);
    put_u32(s, static_cast<std::uint32_t>(chunk_indexes_.count));
    put_u64(s, message_count_ ? start_ns_ : 0);
    put_u64(s, message_count_ ? end_ns_ : 0);
    std::string counts;
    for (std::size_t c = 0; c < channels_.size(); ++c) {
      put_u16(counts, static_cast<std::uint16_t>(c + 1));
      put_u64(counts, channels_[c].count);
    }
    put_str(s, counts);
    add_record(McapOpcode::kStatistics, s);
  });
  group(McapOpcode::kChunkIndex, [&] {
    for (const auto& block : chunk_indexes_.blocks) summary += block;  // whole records already
  });
  for (const McapOpcode op : {McapOpcode::kAttachmentIndex, McapOpcode::kMetadataIndex}) {
    group(op, [&] {
      for (const auto& e : indexes_)
        if (e.op == op) add_record(op, e.content);
    });
  }
  const std::uint64_t summary_offset_start = summary_start + summary.size();
  for (const auto& [op, start, length] : groups) {
    std::string s;
    put_u8(s, static_cast<std::uint8_t>(op));
    put_u64(s, start);
    put_u64(s, length);
    add_record(McapOpcode::kSummaryOffset, s);
  }
  // Footer: the summary CRC covers the summary, the summary offsets and the footer up to it.
  put_u8(summary, static_cast<std::uint8_t>(McapOpcode::kFooter));
  put_u64(summary, 8 + 8 + 4);
  put_u64(summary, summary_start);
  put_u64(summary, summary_offset_start);
  put_u32(summary, crc32(summary));
  summary.append(kMcapMagic);
  put(summary);
  flush_buffer();

  file_.commit();  // synced, 0644, renamed to its name; discarded when that fails
  closed_ = true;
}

}  // namespace mc
