// What an unclosed MCAP file still holds (core/mcap_recover.h): the strict parser's record
// readers, run over the data section until the first record that is cut or inconsistent.
#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/core/mcap_parser.h"

namespace mc::mcap_detail {

McapSalvage Parser::salvage() {
  McapSalvage s;
  s.file_bytes = f_.size();
  if (f_.size() < 8 || f_.substr(0, 8) != kMcapMagic) fail(name_, 0, "not an MCAP file (bad opening magic)");
  footer_ = f_.size();  // no summary to stop at: records may run to the end of the file
  const Record h = frame(8, footer_, "data section");
  if (h.op != static_cast<std::uint8_t>(Op::kHeader))
    fail(name_, 8, fmt::format("expected the Header record after the magic, found {}", op_name(h.op)));
  {
    Fields fl(f_, name_, h.content, h.end, "Header");
    out_.profile = fl.prefixed("profile");
    out_.library = fl.prefixed("library");
  }
  std::uint64_t at = h.end;
  s.whole_bytes = at;
  while (true) {
    // A record that fails leaves nothing of itself behind.
    const std::size_t schemas = out_.schemas.size(), channels = out_.channels.size(),
                      messages = out_.messages.size(), chunks = out_.chunks.size(),
                      metadata_count = out_.metadata.size(), attachments = out_.attachments.size(),
                      chunk_infos = chunks_.size(), attachment_records = attachment_records_.size(),
                      metadata_records = metadata_records_.size();
    const auto counts = counts_;
    try {
      if (at == f_.size()) {
        s.stopped = fmt::format("the file ends after {} bytes, before its DataEnd record", at);
        break;
      }
      const Record r = frame(at, footer_, "data section");
      switch (static_cast<Op>(r.op)) {
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
          break;
        case Op::kAttachment:
          attachment(r);
          break;
        case Op::kMetadata:
          metadata(r);
          break;
        case Op::kDataEnd:
          s.complete = true;
          break;
        case Op::kHeader:
        case Op::kFooter:
        case Op::kChunkIndex:
        case Op::kAttachmentIndex:
        case Op::kStatistics:
        case Op::kMetadataIndex:
        case Op::kSummaryOffset:
          fail(name_, at, fmt::format("{} record in the data section", op_name(r.op)));
        default:
          break;  // MessageIndex records (rebuilt on writing) and unknown opcodes
      }
      at = r.end;
      s.whole_bytes = at;
      if (s.complete) break;
    } catch (const InvalidInput& e) {
      out_.schemas.resize(schemas);
      out_.channels.resize(channels);
      out_.messages.resize(messages);
      out_.chunks.resize(chunks);
      out_.metadata.resize(metadata_count);
      out_.attachments.resize(attachments);
      chunks_.resize(chunk_infos);
      attachment_records_.resize(attachment_records);
      metadata_records_.resize(metadata_records);
      counts_ = counts;
      s.stopped = e.what();
      break;
    }
  }
  out_.chunk_count = out_.chunks.size();
  s.contents = std::move(out_);
  return s;
}

}  // namespace mc::mcap_detail
