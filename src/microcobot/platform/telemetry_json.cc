#include "microcobot/platform/telemetry_json.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include <nlohmann/json.hpp>

#include "microcobot/core/error.h"
#include "microcobot/core/mcap_reader.h"
#include "microcobot/core/mcap_writer.h"
#include "microcobot/platform/platform.h"

namespace mc::platform {

namespace {
bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() > suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}
}  // namespace

std::string_view telemetry_unit(std::string_view name) {
  // Longest suffixes first: "_m_s" also ends in "_s", "_us" too.
  if (ends_with(name, "_m_s")) return "m/s";
  if (ends_with(name, "_us")) return "us";
  if (ends_with(name, "_m")) return "m";
  if (ends_with(name, "_N")) return "N";
  if (ends_with(name, "_V")) return "V";
  if (ends_with(name, "_s")) return "s";
  return "";
}

std::string telemetry_json_schema(std::size_t channel_count) {
  require(channel_count >= 1 && channel_count <= kTelemetryChannels.size(), "telemetry.channel_count",
          "must be in [1, " + std::to_string(kTelemetryChannels.size()) + "]",
          static_cast<double>(channel_count));
  nlohmann::ordered_json props = nlohmann::ordered_json::object();
  for (std::size_t i = 0; i < channel_count; ++i) {
    const std::string_view name = kTelemetryChannels[i];
    const std::string_view unit = telemetry_unit(name);
    std::string description;
    if (unit == "us") {
      description = "microseconds (us)";
    } else if (!unit.empty()) {
      description = "unit: " + std::string(unit);
    } else if (name == "part_phase") {
      description = "the part's phase index (dimensionless)";
    } else {
      description = "flag: 1 true, 0 false";
    }
    description += "; null when not finite";
    props[std::string(name)] = {{"type", {"number", "null"}}, {"description", description}};
  }
  nlohmann::ordered_json schema = {
      {"$schema", "https://json-schema.org/draft/2020-12/schema"},
      {"title", std::string(kTelemetrySchemaName)},
      {"description", "One telemetry sample of the microcobot platform (SI units, names carry the unit)"},
      {"type", "object"},
      {"properties", std::move(props)},
  };
  return schema.dump();
}

void telemetry_to_json(std::span<const double> sample, std::string& out) {
  if (sample.size() > kTelemetryChannels.size()) {
    throw InvalidParams("telemetry sample",
                        "at most " + std::to_string(kTelemetryChannels.size()) + " values",
                        static_cast<double>(sample.size()));
  }
  char buf[40];
  out.push_back('{');
  for (std::size_t i = 0; i < sample.size(); ++i) {
    if (i) out.push_back(',');
    out.push_back('"');
    out.append(kTelemetryChannels[i]);
    out.append("\":");
    const double v = sample[i];
    if (!std::isfinite(v)) {
      out.append("null");
      continue;
    }
    const auto res = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 10);
    out.append(buf, res.ptr);
  }
  out.push_back('}');
}

void write_telemetry_mcap(const Recorder& rec, const std::filesystem::path& file) {
  const std::size_t n = rec.channels();
  McapWriter w(file);
  const auto schema = w.add_schema(kTelemetrySchemaName, "jsonschema", telemetry_json_schema(n));
  const auto channel = w.add_channel(schema, kTelemetryTopic, "json");
  std::vector<double> sample(n);
  std::string json;
  json.reserve(n * 32 + 2);
  for (std::size_t i = 0; i < rec.size(); ++i) {
    for (std::size_t c = 0; c < n; ++c) sample[c] = rec.at(i, c);
    json.clear();
    telemetry_to_json(sample, json);
    // t_s is channel 0; times before 0 or not finite (never in a run) are clamped to 0.
    const double t = sample[0];
    const auto ns = std::isfinite(t) && t > 0 ? static_cast<std::uint64_t>(std::llround(t * 1e9)) : 0;
    w.write(channel, ns, ns, json);
  }
  w.close();
}

Recorder read_telemetry_mcap(const std::filesystem::path& file, std::size_t max_samples) {
  require(max_samples >= 1, "max_samples", "must be >= 1", static_cast<double>(max_samples));
  return telemetry_from_mcap(read_mcap(file), file.string(), max_samples);
}

Recorder telemetry_from_mcap(const McapContents& m, const std::string& name, std::size_t max_samples) {
  require(max_samples >= 1, "max_samples", "must be >= 1", static_cast<double>(max_samples));
  const std::filesystem::path file(name);
  const McapChannel* channel = nullptr;
  for (const auto& c : m.channels)
    if (c.topic == kTelemetryTopic && c.message_encoding == "json") channel = &c;
  if (!channel)
    throw InvalidInput(file.string(), 0, "no " + std::string(kTelemetryTopic) + " channel of JSON messages");
  std::size_t total = 0;
  for (const auto& msg : m.messages) total += msg.channel_id == channel->id;
  if (total == 0) throw InvalidInput(file.string(), 0, "no telemetry message");

  std::vector<std::string> names;
  std::vector<double> values;
  std::unique_ptr<Recorder> rec;
  std::size_t index = 0;
  for (const auto& msg : m.messages) {
    if (msg.channel_id != channel->id) continue;
    auto fail = [&](const std::string& what) {
      throw InvalidInput(file.string(), 0, "telemetry message " + std::to_string(index) + ": " + what);
    };
    const auto j = nlohmann::json::parse(msg.data, nullptr, /*allow_exceptions=*/false);
    if (!j.is_object()) fail("not a JSON object");
    if (!rec) {  // the first message fixes the channels
      if (j.empty() || j.size() > kTelemetryChannels.size()) fail("unexpected number of members");
      for (std::size_t c = 0; c < j.size(); ++c) names.emplace_back(kTelemetryChannels[c]);
      values.resize(names.size());
      rec = std::make_unique<Recorder>(names, std::min(total, max_samples),
                                       (total + max_samples - 1) / max_samples);
    }
    if (j.size() != names.size())
      fail("has " + std::to_string(j.size()) + " members, the first had " + std::to_string(names.size()));
    for (std::size_t c = 0; c < names.size(); ++c) {
      const auto it = j.find(names[c]);
      if (it == j.end()) fail("no member " + names[c]);
      if (it->is_null()) {
        values[c] = std::numeric_limits<double>::quiet_NaN();
      } else if (it->is_number()) {
        values[c] = it->get<double>();
      } else {
        fail(names[c] + " must be a number or null");
      }
    }
    rec->sample(values);
    ++index;
  }
  return std::move(*rec);
}

}  // namespace mc::platform
