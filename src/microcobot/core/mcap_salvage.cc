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
  std::uint64_t at = read_header();
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
      if (!content_record(r)) {
        // MessageIndex records are rebuilt on writing; unknown opcodes skipped.
        if (r.op == static_cast<std::uint8_t>(Op::kDataEnd)) s.complete = true;
        summary_only(r);
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
