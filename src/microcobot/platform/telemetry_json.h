#pragma once
/// @file
/// The platform's telemetry as JSON messages: one object per telemetry sample, keyed by the
/// unit-suffixed names of kTelemetryChannels, with its JSON Schema. Shared by the MCAP
/// recording (`recording.mcap` beside `recording.csv`) and the live server's telemetry topic,
/// so that a viewer sees the same fields in a file and live.

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "microcobot/core/mcap_reader.h"
#include "microcobot/core/recorder.h"

namespace mc::platform {

/// The topic and schema name of the telemetry messages (MCAP channel, Foxglove channel).
inline constexpr std::string_view kTelemetryTopic = "/platform/telemetry";
inline constexpr std::string_view kTelemetrySchemaName = "microcobot.Telemetry";

/// The unit of a channel read off its name's suffix: "m/s" (_m_s), "us" (_us), "m" (_m),
/// "N" (_N), "V" (_V), "s" (_s); "" for the flags and states without a unit (deadman, clutch,
/// engaged, stale: 0 or 1; part_phase: the part's phase index).
std::string_view telemetry_unit(std::string_view name);

/// The JSON Schema (draft 2020-12) of a message of the first `channel_count` channels of
/// kTelemetryChannels: `type: object`, one `number` property per channel, in order, whose
/// `description` gives its unit (or says it is a flag). Throws InvalidParams unless
/// 1 <= channel_count <= kTelemetryChannels.size().
std::string telemetry_json_schema(std::size_t channel_count);

/// Appends `{"t_s":...,"handle_x_m":...,...}` to `out`: one member per value of `sample`,
/// named by kTelemetryChannels in order. Numbers have 10 significant digits (relative rounding
/// below 5e-10, finer than any sensor of the platform); a non-finite value is written `null`,
/// never NaN or Infinity. Allocates only when `out` must grow (reuse it). Throws
/// InvalidParams when `sample` has more values than kTelemetryChannels names.
void telemetry_to_json(std::span<const double> sample, std::string& out);

/// Writes the recording as MCAP to `file` (atomically: temporary name, then rename): one
/// schema (kTelemetrySchemaName, jsonschema), one channel (kTelemetryTopic, json), one message
/// per kept sample whose log and publish times are its `t_s` in nanoseconds. The recording's
/// channels must be the first rec.channels() names of kTelemetryChannels. Throws mc::Error.
void write_telemetry_mcap(const Recorder& rec, const std::filesystem::path& file);

/// Reads a telemetry recording back (what write_telemetry_mcap and `serve` write): the messages
/// of kTelemetryTopic, whose members must be the first N names of kTelemetryChannels (null is
/// read as NaN). Keeps at most `max_samples` samples, evenly decimated (a report's plots need no
/// more). Throws InvalidInput "<file>: ..." for a file that is not such a recording.
Recorder read_telemetry_mcap(const std::filesystem::path& file, std::size_t max_samples);
/// The same from an MCAP file already read (read_mcap); `name` stands for it in errors.
Recorder telemetry_from_mcap(const McapContents& m, const std::string& name, std::size_t max_samples);

}  // namespace mc::platform
