#pragma once
/// @file
/// The platform's telemetry as JSON messages: one object per telemetry sample, keyed by the
/// names of a TelemetrySchema, with its JSON Schema. Shared by the MCAP
/// recording (`recording.mcap` beside `recording.csv`) and the live server's telemetry topic,
/// so that a viewer sees the same fields in a file and live.

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "microcobot/core/mcap_reader.h"
#include "microcobot/core/recorder.h"
#include "microcobot/platform/telemetry_schema.h"

namespace mc::platform {

/// The topic and schema name of the telemetry messages (MCAP channel, Foxglove channel).
inline constexpr std::string_view kTelemetryTopic = "/platform/telemetry";
inline constexpr std::string_view kTelemetrySchemaName = "microcobot.Telemetry";

/// The JSON Schema (draft 2020-12) of a message of `schema`'s channels: `type: object`, one
/// `number` (or null: not finite) property per channel, in order, with its `unit` ("" for flags
/// and indices) and its `description`. Throws InvalidParams for an empty schema.
std::string telemetry_json_schema(const TelemetrySchema& schema);

/// Appends `{"t_s":...,"handle_x_m":...,...}` to `out`: one member per value of `sample`,
/// named by `schema`'s channels in order. Numbers have 10 significant digits (relative rounding
/// below 5e-10, finer than any sensor of the platform); a non-finite value is written `null`,
/// never NaN or Infinity. Allocates only when `out` must grow (reuse it). Throws
/// InvalidParams when `sample` has more values than `schema` has channels.
void telemetry_to_json(const TelemetrySchema& schema, std::span<const double> sample, std::string& out);

/// Writes the recording as MCAP to `file` (atomically: temporary name, then rename): one
/// schema (kTelemetrySchemaName, jsonschema), one channel (kTelemetryTopic, json), one message
/// per kept sample whose log and publish times are its `t_s` in nanoseconds. The recording's
/// channels must be `schema`'s names, in order. Throws mc::Error.
void write_telemetry_mcap(const Recorder& rec, const TelemetrySchema& schema,
                          const std::filesystem::path& file);

/// Reads a telemetry recording back (what write_telemetry_mcap and `serve` write): the messages
/// of kTelemetryTopic, each with the same numeric members, whose names become the recording's
/// channels (null is read as NaN). Keeps at most `max_samples` samples, evenly decimated (a
/// report's plots need no more). Throws InvalidInput "<file>: ..." for a file that is not such
/// a recording.
Recorder read_telemetry_mcap(const std::filesystem::path& file, std::size_t max_samples);
/// The same from an MCAP file already read (read_mcap); `name` stands for it in errors.
Recorder telemetry_from_mcap(const McapContents& m, const std::string& name, std::size_t max_samples);
/// The channels of a telemetry recording, with the units and descriptions its JSON Schema
/// declares (channels missing from the schema get an empty unit). Throws like
/// telemetry_from_mcap.
TelemetrySchema telemetry_schema_from_mcap(const McapContents& m, const std::string& name);

}  // namespace mc::platform
