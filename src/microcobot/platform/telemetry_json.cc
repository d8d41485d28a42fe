#include "microcobot/platform/telemetry_json.h"

#include <charconv>
#include <cmath>
#include <vector>

#include <nlohmann/json.hpp>

#include "microcobot/core/error.h"
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
    props[std::string(name)] = {{"type", "number"}, {"description", description}};
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

}  // namespace mc::platform
