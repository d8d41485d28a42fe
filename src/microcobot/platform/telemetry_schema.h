#pragma once
/// @file
/// The platform's telemetry channels, declared once: each channel's name, unit and meaning, in
/// the order of a sample's values. Everything that shows or stores telemetry reads its names and
/// units from here: the recording's CSV header and MCAP schema, the live server's Foxglove
/// schema, the console, the Python recording's keys and the reference documentation.
///
/// A platform's schema is its built-in channels (platform_telemetry.cc declares each with the
/// function that reads it off the platform) followed by the channels added to it
/// (Platform::add_telemetry_channel): adding a channel is one call, and it appears in every
/// output with its name and unit.

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace mc::platform {

/// One channel of a telemetry sample.
struct TelemetryChannel {
  /// The column and member name: lower-case words joined by '_', ending with the unit
  /// ("_m", "_N", "_V", "_rad", "_s", "_us", "_m_s" for m/s) unless the channel has none.
  std::string name;
  /// The SI unit ("m", "N", "V", "rad", "s", "us", "m/s"), or "" for flags (0 or 1) and indices.
  std::string unit;
  /// What the channel is, in one line (the reference documentation and the schemas show it).
  std::string description;

  bool operator==(const TelemetryChannel&) const = default;
};

/// The most channels a sample holds (the fixed-size sample the loop's ring carries).
inline constexpr std::size_t kMaxTelemetryChannels = 64;
/// One telemetry sample: the first TelemetrySchema::size() values count.
using TelemetrySample = std::array<double, kMaxTelemetryChannels>;

/// The ordered channels of one platform's telemetry.
class TelemetrySchema {
 public:
  TelemetrySchema() = default;

  /// Appends a channel and returns its index. Throws mc::InvalidParams naming the channel when
  /// its name is empty, not of [a-z0-9_] (capital letters allowed in a unit suffix such as
  /// "_N" or "_V"), already used, or not ending with its unit's suffix; or when the schema
  /// already holds kMaxTelemetryChannels.
  std::size_t add(TelemetryChannel channel);

  std::size_t size() const { return channels_.size(); }
  bool empty() const { return channels_.empty(); }
  const TelemetryChannel& operator[](std::size_t i) const { return channels_[i]; }
  auto begin() const { return channels_.begin(); }
  auto end() const { return channels_.end(); }

  /// The index of channel `name`, or nothing.
  std::optional<std::size_t> find(std::string_view name) const;
  /// The index of channel `name`; throws mc::InvalidParams when there is none.
  std::size_t index(std::string_view name) const;
  /// The names in order (a Recorder's columns).
  std::vector<std::string> names() const;
  /// The first `count` channels (count <= size()).
  TelemetrySchema first(std::size_t count) const;

  bool operator==(const TelemetrySchema&) const = default;

 private:
  std::vector<TelemetryChannel> channels_;
};

/// The suffix a channel name with `unit` ends with: "_" and the unit with '/' as '_'
/// ("m/s" -> "_m_s"); "" for a channel without unit.
std::string telemetry_unit_suffix(std::string_view unit);

/// The built-in channels of a platform: what the loop sees on any devices, then, when
/// `simulation`, the simulation's ground truth (the operator's hand, the true carriage
/// positions, the haptic channels, the part), which only a simulated platform records.
/// Defined with their sources in platform_telemetry.cc.
const TelemetrySchema& builtin_telemetry(bool simulation);
/// How many of the built-in channels the loop records on any devices (the first ones).
std::size_t loop_channel_count();
/// The index of built-in channel `name` in any platform's sample (the built-in channels come
/// first, in the same order, on every platform). Throws mc::InvalidParams for an unknown name.
std::size_t telemetry_channel_index(std::string_view name);

}  // namespace mc::platform
