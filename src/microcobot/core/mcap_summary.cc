// The summary of an MCAP file checked against its data section (core/mcap_reader.h lists the
// checks).

#include <map>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/core/mcap_parser.h"

namespace mc::mcap_detail {

void Parser::read_summary(std::uint64_t data_end) {
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
         fmt::format("footer's summary_offset_start {} is outside [{}, {}]", summary_offset_start_, data_end,
                     footer_));
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
    fail(
        name_, summary_start_,
        fmt::format("summary indexes {} of {} attachments and {} of {} metadata records", attachment_indexes_,
                    attachment_records_.size(), metadata_indexes_, metadata_records_.size()));
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

// An index record of the summary must point at the next Attachment/Metadata record, by name.
void Parser::check_index(const Record& r, const char* what, std::uint64_t offset, std::uint64_t length,
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

void Parser::attachment_index(const Record& r) {
  Fields fl(f_, name_, r.content, r.end, "AttachmentIndex");
  const std::uint64_t offset = fl.u64("offset"), length = fl.u64("length");
  fl.u64("log_time");
  fl.u64("create_time");
  fl.u64("data_size");
  const std::string name(fl.prefixed("name"));
  fl.prefixed("media_type");
  check_index(r, "AttachmentIndex", offset, length, name, attachment_records_, attachment_indexes_);
}

void Parser::metadata_index(const Record& r) {
  Fields fl(f_, name_, r.content, r.end, "MetadataIndex");
  const std::uint64_t offset = fl.u64("offset"), length = fl.u64("length");
  const std::string name(fl.prefixed("name"));
  check_index(r, "MetadataIndex", offset, length, name, metadata_records_, metadata_indexes_);
}

void Parser::statistics(const Record& r) {
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

void Parser::chunk_index(const Record& r, const ChunkInfo& ci) {
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
           fmt::format("ChunkIndex {} is {}, the chunk at byte {} has {}", field, stored, ci.offset, actual));
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

}  // namespace mc::mcap_detail
