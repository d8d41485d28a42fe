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

namespace mc::platform {

std::string telemetry_json_schema(const TelemetrySchema& schema) {
  require(!schema.empty(), "telemetry schema", "has no channel");
  nlohmann::ordered_json props = nlohmann::ordered_json::object();
  for (const auto& c : schema)
    props[c.name] = {{"type", {"number", "null"}}, {"unit", c.unit}, {"description", c.description}};
  nlohmann::ordered_json json = {
      {"$schema", "https://json-schema.org/draft/2020-12/schema"},
      {"title", std::string(kTelemetrySchemaName)},
      {"description",
       "One telemetry sample of the microcobot platform: SI units, each property's `unit` (\"\" for flags "
       "and "
       "indices) ending its name; null for a value that is not finite"},
      {"type", "object"},
      {"properties", std::move(props)},
  };
  return json.dump();
}

void telemetry_to_json(const TelemetrySchema& schema, std::span<const double> sample, std::string& out) {
  if (sample.size() > schema.size()) {
    throw InvalidParams("telemetry sample", "at most " + std::to_string(schema.size()) + " values",
                        static_cast<double>(sample.size()));
  }
  char buf[40];
  out.push_back('{');
  for (std::size_t i = 0; i < sample.size(); ++i) {
    if (i) out.push_back(',');
    out.push_back('"');
    out.append(schema[i].name);
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

void write_telemetry_mcap(const Recorder& rec, const TelemetrySchema& schema,
                          const std::filesystem::path& file) {
  const std::size_t n = rec.channels();
  require(n == schema.size(), "telemetry recording", "must have the schema's channels",
          static_cast<double>(n));
  for (std::size_t c = 0; c < n; ++c)
    require(rec.has_channel(schema[c].name), "telemetry recording", "lacks channel " + schema[c].name);
  McapWriter w(file);
  const auto schema_id = w.add_schema(kTelemetrySchemaName, "jsonschema", telemetry_json_schema(schema));
  const auto channel = w.add_channel(schema_id, kTelemetryTopic, "json");
  std::vector<double> sample(n);
  std::string json;
  json.reserve(n * 32 + 2);
  for (std::size_t i = 0; i < rec.size(); ++i) {
    for (std::size_t c = 0; c < n; ++c) sample[c] = rec.at(i, c);
    json.clear();
    telemetry_to_json(schema, sample, json);
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

namespace {

const McapChannel& telemetry_channel(const McapContents& m, const std::string& name) {
  for (const auto& c : m.channels)
    if (c.topic == kTelemetryTopic && c.message_encoding == "json") return c;
  throw InvalidInput(name, 0, "no " + std::string(kTelemetryTopic) + " channel of JSON messages");
}

// The unit a recording written before the schema declared units carries in its names.
std::string unit_of_suffix(std::string_view n) {
  for (const char* unit : {"m/s", "rad", "us", "m", "N", "V", "s"}) {
    const std::string suffix = telemetry_unit_suffix(unit);
    if (n.size() > suffix.size() && n.ends_with(suffix)) return unit;
  }
  return {};
}

}  // namespace

Recorder telemetry_from_mcap(const McapContents& m, const std::string& name, std::size_t max_samples) {
  require(max_samples >= 1, "max_samples", "must be >= 1", static_cast<double>(max_samples));
  const McapChannel& channel = telemetry_channel(m, name);
  std::size_t total = 0;
  for (const auto& msg : m.messages) total += msg.channel_id == channel.id;
  if (total == 0) throw InvalidInput(name, 0, "no telemetry message");

  std::vector<std::string> names;
  std::vector<double> values;
  std::unique_ptr<Recorder> rec;
  std::size_t index = 0;
  for (const auto& msg : m.messages) {
    if (msg.channel_id != channel.id) continue;
    auto fail = [&](const std::string& what) {
      throw InvalidInput(name, 0, "telemetry message " + std::to_string(index) + ": " + what);
    };
    // Ordered: the members' order is the channels' (the schema's).
    const auto j = nlohmann::ordered_json::parse(msg.data, nullptr, /*allow_exceptions=*/false);
    if (!j.is_object()) fail("not a JSON object");
    if (!rec) {  // the first message fixes the channels
      if (j.empty() || j.size() > kMaxTelemetryChannels) fail("unexpected number of members");
      for (const auto& item : j.items()) names.push_back(item.key());
      values.resize(names.size());
      rec = std::make_unique<Recorder>(names, std::min(total, max_samples),
                                       (total + max_samples - 1) / max_samples);
    }
    if (j.size() != names.size())
      fail("has " + std::to_string(j.size()) + " members, the first had " + std::to_string(names.size()));
    std::size_t c = 0;
    for (const auto& item : j.items()) {
      if (item.key() != names[c])
        fail("member " + std::to_string(c) + " is " + item.key() + ", not " + names[c]);
      const auto& v = item.value();
      if (v.is_null()) {
        values[c] = std::numeric_limits<double>::quiet_NaN();
      } else if (v.is_number()) {
        values[c] = v.get<double>();
      } else {
        fail(names[c] + " must be a number or null");
      }
      ++c;
    }
    rec->sample(values);
    ++index;
  }
  return std::move(*rec);
}

TelemetrySchema telemetry_schema_from_mcap(const McapContents& m, const std::string& name) {
  const McapChannel& channel = telemetry_channel(m, name);
  const McapSchema* schema = m.schema(channel.schema_id);
  if (schema == nullptr || schema->encoding != "jsonschema")
    throw InvalidInput(name, 0, std::string(kTelemetryTopic) + " has no JSON Schema");
  const auto j = nlohmann::ordered_json::parse(schema->data, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object() || !j.contains("properties") || !j["properties"].is_object())
    throw InvalidInput(name, 0, std::string(kTelemetryTopic) + "'s schema has no properties");
  TelemetrySchema out;
  for (const auto& item : j["properties"].items()) {
    const auto& p = item.value();
    TelemetryChannel c{item.key(), unit_of_suffix(item.key()), ""};
    if (p.is_object() && p.contains("unit") && p["unit"].is_string()) c.unit = p["unit"].get<std::string>();
    if (p.is_object() && p.contains("description") && p["description"].is_string())
      c.description = p["description"].get<std::string>();
    try {
      out.add(std::move(c));
    } catch (const Error& e) {
      throw InvalidInput(name, 0, std::string(kTelemetryTopic) + "'s schema: " + e.what());
    }
  }
  return out;
}

}  // namespace mc::platform
