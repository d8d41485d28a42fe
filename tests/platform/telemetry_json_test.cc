#include "microcobot/platform/telemetry_json.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include <nlohmann/json.hpp>

#include "microcobot/core/error.h"
#include "microcobot/core/mcap_reader.h"
#include "microcobot/platform/platform.h"
#include "support/test_support.h"

namespace mc::platform {
namespace {

const TelemetrySchema& all() { return builtin_telemetry(true); }

TEST(TelemetryJson, TheSchemaHasOneNumberPropertyPerChannelInOrderWithItsUnit) {
  for (const bool simulation : {false, true}) {
    const TelemetrySchema& channels = builtin_telemetry(simulation);
    const auto schema = nlohmann::ordered_json::parse(telemetry_json_schema(channels));
    EXPECT_EQ(schema["type"], "object");
    EXPECT_EQ(schema["title"], "microcobot.Telemetry");
    const auto& props = schema["properties"];
    ASSERT_EQ(props.size(), channels.size());
    std::size_t i = 0;
    for (const auto& [name, p] : props.items()) {
      EXPECT_EQ(name, channels[i].name);
      EXPECT_EQ(p["unit"], channels[i].unit);
      EXPECT_EQ(p["type"], nlohmann::ordered_json::array({"number", "null"}));  // null: not finite
      EXPECT_EQ(p["description"], channels[i].description);
      ++i;
    }
  }
  const auto schema = nlohmann::json::parse(telemetry_json_schema(all()));
  EXPECT_EQ(schema["properties"]["handle_x_m"]["unit"], "m");
  EXPECT_EQ(schema["properties"]["tick_us"]["unit"], "us");
  EXPECT_EQ(schema["properties"]["deadman"]["unit"], "");
  EXPECT_THROW(telemetry_json_schema(TelemetrySchema{}), InvalidParams);
}

TEST(TelemetryJson, MessagesAreValidJsonWithTenDigitsAndNoNaN) {
  std::vector<double> sample(all().size());
  for (std::size_t i = 0; i < sample.size(); ++i)
    sample[i] = std::pow(-1.0, i) * 1.234567890123e-7 * (i + 1.0);
  sample[0] = 12.3456789012345;
  sample[3] = 1.0;  // a flag
  sample[5] = std::numeric_limits<double>::quiet_NaN();
  sample[6] = std::numeric_limits<double>::infinity();
  std::string out = "prefix";
  telemetry_to_json(all(), sample, out);
  ASSERT_EQ(out.substr(0, 6), "prefix");  // appended
  EXPECT_EQ(out.find("nan"), std::string::npos);
  EXPECT_EQ(out.find("inf"), std::string::npos);
  EXPECT_NE(out.find("\"deadman\":1,"), std::string::npos) << out;
  const auto j = nlohmann::ordered_json::parse(out.substr(6));
  ASSERT_EQ(j.size(), sample.size());
  std::size_t i = 0;
  for (const auto& [name, v] : j.items()) {
    EXPECT_EQ(name, all()[i].name);
    if (i == 5 || i == 6) {
      EXPECT_TRUE(v.is_null()) << name;
    } else {
      EXPECT_NEAR(v.get<double>(), sample[i], 5e-10 * std::abs(sample[i])) << name;
    }
    ++i;
  }
  // Fewer values: the loop channels only.
  out.clear();
  telemetry_to_json(all(), std::span<const double>(sample).first(loop_channel_count()), out);
  EXPECT_EQ(nlohmann::json::parse(out).size(), loop_channel_count());
  EXPECT_THROW(telemetry_to_json(all(), std::vector<double>(all().size() + 1), out), InvalidParams);
}

TEST(TelemetryJson, ARecordingBecomesAnMcapFile) {
  const TelemetrySchema& loop = builtin_telemetry(false);
  Recorder rec(loop.names(), 100);
  std::vector<double> s(loop.size(), 0.5);
  for (int i = 0; i < 100; ++i) {
    s[0] = 1e-3 * i;
    rec.sample(s);
  }
  test::TempDir dir;
  write_telemetry_mcap(rec, loop, dir / "recording.mcap");
  const auto m = read_mcap(dir / "recording.mcap");
  ASSERT_EQ(m.schemas.size(), 1u);
  EXPECT_EQ(m.schemas[0].name, "microcobot.Telemetry");
  EXPECT_EQ(m.schemas[0].encoding, "jsonschema");
  EXPECT_EQ(m.schemas[0].data, telemetry_json_schema(loop));
  ASSERT_EQ(m.channels.size(), 1u);
  EXPECT_EQ(m.channels[0].topic, "/platform/telemetry");
  EXPECT_EQ(m.channels[0].message_encoding, "json");
  ASSERT_EQ(m.messages.size(), 100u);
  EXPECT_EQ(m.statistics.message_count, 100u);
  for (std::size_t i = 0; i < 100; ++i) {
    EXPECT_EQ(m.messages[i].log_time_ns, 1'000'000 * i);
    const auto j = nlohmann::json::parse(m.messages[i].data);
    EXPECT_NEAR(j["t_s"].get<double>(), 1e-3 * static_cast<double>(i), 1e-15);
    EXPECT_EQ(j["handle_x_m"].get<double>(), 0.5);
  }
  // Read back: the same channels in the same order, with their units.
  EXPECT_EQ(telemetry_schema_from_mcap(m, "recording.mcap"), loop);
  const Recorder back = telemetry_from_mcap(m, "recording.mcap", 1000);
  EXPECT_EQ(back.to_table().names(), loop.names());
  EXPECT_EQ(back.size(), 100u);
  // A recording whose channels are not the schema's is refused, not written wrong.
  EXPECT_THROW(write_telemetry_mcap(rec, all(), dir / "wrong.mcap"), InvalidParams);
  EXPECT_FALSE(std::filesystem::exists(dir / "wrong.mcap"));
}

}  // namespace
}  // namespace mc::platform
