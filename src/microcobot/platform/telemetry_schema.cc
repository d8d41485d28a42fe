#include "microcobot/platform/telemetry_schema.h"

#include <algorithm>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"

namespace mc::platform {

std::string telemetry_unit_suffix(std::string_view unit) {
  if (unit.empty()) return {};
  std::string s = "_" + std::string(unit);
  std::replace(s.begin(), s.end(), '/', '_');
  return s;
}

std::size_t TelemetrySchema::add(TelemetryChannel channel) {
  const std::string field = "telemetry channel '" + excerpt(channel.name) + "'";
  require(!channel.name.empty(), "telemetry channel", "needs a name");
  const std::string suffix = telemetry_unit_suffix(channel.unit);
  const std::string_view stem =
      std::string_view(channel.name)
          .substr(0, channel.name.size() >= suffix.size() ? channel.name.size() - suffix.size() : 0);
  require(
      channel.name.size() > suffix.size() && channel.name.ends_with(suffix), field,
      channel.unit.empty() ? std::string("has no unit") : "must end with its unit's suffix '" + suffix + "'");
  require(std::all_of(stem.begin(), stem.end(),
                      [](char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_'; }),
          field, "must be lower-case letters, digits and '_' (then its unit)");
  require(suffix.empty() || std::all_of(suffix.begin(), suffix.end(),
                                        [](char c) {
                                          return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
                                        }),
          field, "has a unit that is not letters and '/'");
  require(!find(channel.name), field, "is declared twice");
  require(channels_.size() < kMaxTelemetryChannels, field,
          "is one too many: a sample holds at most " + std::to_string(kMaxTelemetryChannels) + " channels");
  channels_.push_back(std::move(channel));
  return channels_.size() - 1;
}

std::optional<std::size_t> TelemetrySchema::find(std::string_view name) const {
  for (std::size_t i = 0; i < channels_.size(); ++i)
    if (channels_[i].name == name) return i;
  return std::nullopt;
}

std::size_t TelemetrySchema::index(std::string_view name) const {
  const auto i = find(name);
  if (!i)
    throw InvalidParams("telemetry channel '" + excerpt(std::string(name)) + "'", "is not in the telemetry");
  return *i;
}

std::vector<std::string> TelemetrySchema::names() const {
  std::vector<std::string> out;
  out.reserve(channels_.size());
  for (const auto& c : channels_) out.push_back(c.name);
  return out;
}

TelemetrySchema TelemetrySchema::first(std::size_t count) const {
  require(count <= channels_.size(), "telemetry channels", "more asked than the schema has",
          static_cast<double>(count));
  TelemetrySchema s;
  s.channels_.assign(channels_.begin(), channels_.begin() + static_cast<std::ptrdiff_t>(count));
  return s;
}

std::size_t telemetry_channel_index(std::string_view name) { return builtin_telemetry(true).index(name); }

}  // namespace mc::platform
