#include "microcobot/core/mcap_recover.h"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <map>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/core/mcap_parser.h"
#include "microcobot/core/mcap_writer.h"

namespace mc {

McapSalvage salvage_mcap(std::string_view bytes, const std::string& name) {
  return mcap_detail::Parser(bytes, name).salvage();
}

McapRecovery recover_mcap(const std::filesystem::path& in, const std::filesystem::path& out) {
  std::ifstream file(in, std::ios::binary);
  if (!file) throw InvalidInput(in.string(), 0, "cannot open");
  const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  if (file.bad()) throw InvalidInput(in.string(), 0, "read failed");
  McapRecovery r;
  r.salvage = salvage_mcap(bytes, in.string());
  McapContents& c = r.salvage.contents;

  const bool zstd = std::any_of(c.chunks.begin(), c.chunks.end(),
                                [](const McapChunkStorage& s) { return s.compression == "zstd"; });
  // Chunks of a few MiB: a recording with images holds several frames in each.
  McapWriter w(out, std::size_t{4} << 20, McapCompression{zstd, 1});
  std::map<std::uint16_t, std::uint16_t> schema_id, channel_id;  // the input's id -> the output's
  for (const McapSchema& s : c.schemas) schema_id[s.id] = w.add_schema(s.name, s.encoding, s.data);
  for (const McapChannel& ch : c.channels) {
    const std::uint16_t schema = ch.schema_id == 0 ? 0 : schema_id.at(ch.schema_id);
    channel_id[ch.id] = w.add_channel(schema, ch.topic, ch.message_encoding, ch.metadata);
  }
  for (const McapMetadata& m : c.metadata) w.add_metadata(m.name, m.entries);
  for (const McapAttachment& a : c.attachments)
    w.add_attachment(a.name, a.media_type, a.data, a.log_time_ns, a.create_time_ns);
  std::uint64_t first = 0, last = 0;
  for (const McapMessage& m : c.messages) {
    w.write(channel_id.at(m.channel_id), m.log_time_ns, m.publish_time_ns, m.data);
    first = r.messages == 0 ? m.log_time_ns : std::min(first, m.log_time_ns);
    last = std::max(last, m.log_time_ns);
    ++r.messages;
  }
  r.duration_s = r.messages == 0 ? 0.0 : 1e-9 * static_cast<double>(last - first);
  w.add_metadata("recovery", {{"from", in.filename().string()},
                              {"kept_bytes", std::to_string(r.salvage.whole_bytes)},
                              {"file_bytes", std::to_string(r.salvage.file_bytes)},
                              {"complete", r.salvage.complete ? "true" : "false"},
                              {"stopped", r.salvage.stopped}});
  w.close();
  c.messages.clear();
  c.messages.shrink_to_fit();
  return r;
}

}  // namespace mc
