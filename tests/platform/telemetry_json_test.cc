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

TEST(TelemetryJson, UnitsAreReadOffTheNames) {
  EXPECT_EQ(telemetry_unit("t_s"), "s");
  EXPECT_EQ(telemetry_unit("handle_x_m"), "m");
  EXPECT_EQ(telemetry_unit("grip_force_N"), "N");
  EXPECT_EQ(telemetry_unit("u_x_V"), "V");
  EXPECT_EQ(telemetry_unit("tick_us"), "us");
  EXPECT_EQ(telemetry_unit("speed_m_s"), "m/s");
  EXPECT_EQ(telemetry_unit("deadman"), "");
  EXPECT_EQ(telemetry_unit("part_phase"), "");
}

TEST(TelemetryJson, TheSchemaHasOneNumberPropertyPerChannelInOrder) {
  for (const std::size_t n : {kLoopChannelCount, kTelemetryChannels.size()}) {
    const auto schema = nlohmann::ordered_json::parse(telemetry_json_schema(n));
    EXPECT_EQ(schema["type"], "object");
    EXPECT_EQ(schema["title"], "microcobot.Telemetry");
    const auto& props = schema["properties"];
    ASSERT_EQ(props.size(), n);
    std::size_t i = 0;
    for (const auto& [name, p] : props.items()) {
      EXPECT_EQ(name, kTelemetryChannels[i++]);
      EXPECT_EQ(p["type"], nlohmann::ordered_json::array({"number", "null"}));  // null: not finite
      EXPECT_TRUE(p["description"].is_string());
    }
  }
  const auto schema = nlohmann::json::parse(telemetry_json_schema(kTelemetryChannels.size()));
  EXPECT_NE(schema["properties"]["handle_x_m"]["description"].get<std::string>().find("unit: m"),
            std::string::npos);
  EXPECT_NE(schema["properties"]["tick_us"]["description"].get<std::string>().find("microseconds"),
            std::string::npos);
  EXPECT_NE(schema["properties"]["deadman"]["description"].get<std::string>().find("flag"),
            std::string::npos);
  EXPECT_THROW(telemetry_json_schema(0), InvalidParams);
  EXPECT_THROW(telemetry_json_schema(kTelemetryChannels.size() + 1), InvalidParams);
}

TEST(TelemetryJson, MessagesAreValidJsonWithTenDigitsAndNoNaN) {
  std::vector<double> sample(kTelemetryChannels.size());
  for (std::size_t i = 0; i < sample.size(); ++i)
    sample[i] = std::pow(-1.0, i) * 1.234567890123e-7 * (i + 1.0);
  sample[0] = 12.3456789012345;
  sample[3] = 1.0;  // a flag
  sample[5] = std::numeric_limits<double>::quiet_NaN();
  sample[6] = std::numeric_limits<double>::infinity();
  std::string out = "prefix";
  telemetry_to_json(sample, out);
  ASSERT_EQ(out.substr(0, 6), "prefix");  // appended
  EXPECT_EQ(out.find("nan"), std::string::npos);
  EXPECT_EQ(out.find("inf"), std::string::npos);
  EXPECT_NE(out.find("\"deadman\":1,"), std::string::npos) << out;
  const auto j = nlohmann::ordered_json::parse(out.substr(6));
  ASSERT_EQ(j.size(), sample.size());
  std::size_t i = 0;
  for (const auto& [name, v] : j.items()) {
    EXPECT_EQ(name, kTelemetryChannels[i]);
    if (i == 5 || i == 6) {
      EXPECT_TRUE(v.is_null()) << name;
    } else {
      EXPECT_NEAR(v.get<double>(), sample[i], 5e-10 * std::abs(sample[i])) << name;
    }
    ++i;
  }
  // Fewer values: the loop channels only.
  out.clear();
  telemetry_to_json(std::span<const double>(sample).first(kLoopChannelCount), out);
  EXPECT_EQ(nlohmann::json::parse(out).size(), kLoopChannelCount);
  EXPECT_THROW(telemetry_to_json(std::vector<double>(kTelemetryChannels.size() + 1), out), InvalidParams);
}

TEST(TelemetryJson, ARecordingBecomesAnMcapFile) {
  const std::vector<std::string> names(kTelemetryChannels.begin(),
                                       kTelemetryChannels.begin() + kLoopChannelCount);
  Recorder rec(names, 100);
  std::vector<double> s(kLoopChannelCount, 0.5);
  for (int i = 0; i < 100; ++i) {
    s[0] = 1e-3 * i;
    rec.sample(s);
  }
  test::TempDir dir;
  write_telemetry_mcap(rec, dir / "recording.mcap");
  const auto m = read_mcap(dir / "recording.mcap");
  ASSERT_EQ(m.schemas.size(), 1u);
  EXPECT_EQ(m.schemas[0].name, "microcobot.Telemetry");
  EXPECT_EQ(m.schemas[0].encoding, "jsonschema");
  EXPECT_EQ(m.schemas[0].data, telemetry_json_schema(kLoopChannelCount));
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
}

}  // namespace
}  // namespace mc::platform
