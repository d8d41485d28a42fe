// `microcobot recording`: what an MCAP recording holds (`info`), and recovering one its writer
// never closed (`recover`), as `serve` does at start for its own (docs/console.md, "Recordings").

#include <algorithm>
#include <filesystem>
#include <map>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/core/error.h"
#include "microcobot/core/mcap_reader.h"
#include "microcobot/core/mcap_recover.h"
#include "microcobot/live/recording_recovery.h"

namespace recording_commands {
namespace {

struct InfoOptions {
  mc::cli::CommonOptions common;
  std::filesystem::path file;
};

struct RecoverOptions {
  mc::cli::CommonOptions common;
  std::filesystem::path file;
  std::optional<std::filesystem::path> to;
};

void run_info(const InfoOptions& o) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(o.file, ec))
    throw mc::InvalidInput(o.file.string() + ": no such file");
  mc::McapContents c;
  try {
    c = mc::read_mcap(o.file);
  } catch (const mc::InvalidInput& e) {
    throw mc::InvalidInput(std::string(e.what()) +
                           " (a recording left unfinished by a crash: `microcobot recording recover " +
                           o.file.string() + "`)");
  }
  struct PerChannel {
    std::uint64_t messages = 0, bytes = 0, first = 0, last = 0;
  };
  std::map<std::uint16_t, PerChannel> per;
  std::uint64_t first = 0, last = 0;
  for (const mc::McapMessage& m : c.messages) {
    PerChannel& p = per[m.channel_id];
    p.first = p.messages == 0 ? m.log_time_ns : std::min(p.first, m.log_time_ns);
    p.last = std::max(p.last, m.log_time_ns);
    ++p.messages;
    p.bytes += m.data.size();
    first = first == 0 ? m.log_time_ns : std::min(first, m.log_time_ns);
    last = std::max(last, m.log_time_ns);
  }
  const double duration = c.messages.empty() ? 0.0 : 1e-9 * static_cast<double>(last - first);
  nlohmann::json channels = nlohmann::json::array();
  std::string text = fmt::format(
      "{}: {} messages over {:.3f} s, {} bytes in {} chunks ({})\n", o.file.string(), c.messages.size(),
      duration, std::filesystem::file_size(o.file), c.chunk_count,
      c.chunks.empty() ? "no chunks"
                       : "compression: " + (c.chunks[0].compression.empty() ? std::string("none")
                                                                            : c.chunks[0].compression));
  text +=
      fmt::format("  {:<32} {:>9} {:>12} {:>10}  {}\n", "topic", "messages", "bytes", "rate (Hz)", "schema");
  for (const mc::McapChannel& ch : c.channels) {
    const PerChannel p = per.count(ch.id) ? per.at(ch.id) : PerChannel{};
    const double span = 1e-9 * static_cast<double>(p.last - p.first);
    const double rate = p.messages > 1 && span > 0.0 ? static_cast<double>(p.messages - 1) / span : 0.0;
    const mc::McapSchema* s = c.schema(ch.schema_id);
    const std::string schema = s ? s->name : "";
    channels.push_back({{"topic", ch.topic},
                        {"encoding", ch.message_encoding},
                        {"schema", schema},
                        {"messages", p.messages},
                        {"bytes", p.bytes},
                        {"rate_Hz", rate}});
    text += fmt::format("  {:<32} {:>9} {:>12} {:>10.1f}  {}\n", ch.topic, p.messages, p.bytes, rate, schema);
  }
  nlohmann::json summary{{"file", o.file.string()},       {"bytes", std::filesystem::file_size(o.file)},
                         {"messages", c.messages.size()}, {"duration_s", duration},
                         {"chunks", c.chunk_count},       {"channels", channels}};
  // How the camera was recorded (serve --record-video): its format, channel and encoder settings.
  if (const mc::McapMetadata* v = c.find_metadata("video")) {
    nlohmann::json video = nlohmann::json::object();
    for (const auto& [k, value] : v->entries) video[k] = value;
    const std::string* format = v->find("format");
    const std::string* topic = v->find("topic");
    text += "  video: " + (format ? *format : std::string("?"));
    if (topic) {
      for (const mc::McapChannel& ch : c.channels) {
        if (ch.topic != *topic || !per.count(ch.id)) continue;
        const PerChannel& p = per.at(ch.id);
        const double span = 1e-9 * static_cast<double>(p.last - p.first);
        const double per_minute = span > 0.0 ? 60.0 * static_cast<double>(p.bytes) / span : 0.0;
        video["frames"] = p.messages;
        video["bytes_per_minute"] = per_minute;
        text += fmt::format(" on {}: {} frames, {:.1f} MB a minute", *topic, p.messages, 1e-6 * per_minute);
      }
    }
    if (format && *format == "h264") {
      const auto entry = [&](const char* key) {
        const std::string* e = v->find(key);
        return e ? *e : std::string("?");
      };
      text += fmt::format(" (libx264 {}{}, crf {}, a keyframe every {} s at most, no B-frames)",
                          entry("preset"), entry("tune").empty() ? std::string() : "/" + entry("tune"),
                          entry("crf"), entry("keyframe_interval_s"));
    }
    text += "\n";
    summary["video"] = video;
  }
  if (const mc::McapMetadata* r = c.find_metadata("recovery")) {
    nlohmann::json rec = nlohmann::json::object();
    for (const auto& [k, v] : r->entries) rec[k] = v;
    summary["recovery"] = rec;
    const std::string* from = r->find("from");
    text += "  recovered from " + (from ? *from : std::string("?")) + "\n";
  }
  mc::cli::emit(o.common, summary, text);
}

void run_recover(const RecoverOptions& o) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(o.file, ec))
    throw mc::InvalidInput(o.file.string() + ": no such file");
  std::filesystem::path to;
  if (o.to) {
    to = *o.to;
  } else if (const auto stem = mc::live::unfinished_recording_stem(o.file)) {
    to = o.file.parent_path() / (*stem + ".mcap");  // the name serve would have given it
  } else {
    to = o.file.parent_path() / (o.file.stem().string() + "-recovered.mcap");
  }
  if (std::filesystem::exists(to, ec))
    throw mc::UsageError(to.string() + " exists: name another file with --to");
  const mc::McapRecovery r = mc::recover_mcap(o.file, to);
  const std::uint64_t lost = r.salvage.file_bytes - r.salvage.whole_bytes;
  nlohmann::json summary{{"from", o.file.string()},
                         {"to", to.string()},
                         {"messages", r.messages},
                         {"duration_s", r.duration_s},
                         {"complete", r.salvage.complete},
                         {"kept_bytes", r.salvage.whole_bytes},
                         {"lost_bytes", lost},
                         {"stopped", r.salvage.stopped}};
  const std::string text =
      fmt::format("recovered {}: {} messages over {:.3f} s; {} of {} bytes kept{}", to.string(), r.messages,
                  r.duration_s, r.salvage.whole_bytes, r.salvage.file_bytes,
                  r.salvage.complete ? " (the data were complete)" : "; stopped at: " + r.salvage.stopped);
  mc::cli::emit(o.common, summary, text);
}

void add_recording(CLI::App& group) {
  group.require_subcommand(1);
  {
    auto o = std::make_shared<InfoOptions>();
    auto* cmd =
        group.add_subcommand("info", "Channels, message counts, rates, sizes and duration of an MCAP file");
    cmd->add_option("FILE", o->file, "The MCAP file (read and checked whole)")->required();
    cmd->add_flag("--json", o->common.json, "Print a machine-readable JSON summary on stdout");
    cmd->callback([o] { run_info(*o); });
  }
  {
    auto o = std::make_shared<RecoverOptions>();
    auto* cmd = group.add_subcommand(
        "recover",
        "Recover an MCAP file its writer never closed (a crash): every whole chunk, indexed again");
    cmd->add_option("FILE", o->file,
                    "The unfinished file (serve's .recording-<stamp>.mcap.<random>, or any MCAP)")
        ->required();
    cmd->add_option("--to", o->to,
                    "The recovered file (default: recording-<stamp>.mcap for serve's, else FILE's stem "
                    "+ -recovered.mcap, beside FILE)");
    cmd->add_flag("--json", o->common.json, "Print a machine-readable JSON summary on stdout");
    cmd->callback([o] { run_recover(*o); });
  }
}

const bool kRegistered = mc::cli::register_group(
    {"recording", "What an MCAP recording holds; recovering one a crash left unfinished", 95,
     &add_recording});

}  // namespace
}  // namespace recording_commands
