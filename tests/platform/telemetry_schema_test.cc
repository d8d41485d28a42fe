#include "microcobot/platform/telemetry_schema.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "microcobot/core/error.h"

namespace mc::platform {
namespace {

TEST(TelemetrySchema, EveryBuiltinChannelHasAUnitSuffixAndADescription) {
  const TelemetrySchema& all = builtin_telemetry(true);
  ASSERT_GT(all.size(), loop_channel_count());
  EXPECT_EQ(all.first(loop_channel_count()), builtin_telemetry(false));  // the loop's come first
  std::set<std::string> names;
  for (const auto& c : all) {
    EXPECT_TRUE(names.insert(c.name).second) << c.name;
    EXPECT_FALSE(c.description.empty()) << c.name;
    EXPECT_TRUE(c.name.ends_with(telemetry_unit_suffix(c.unit))) << c.name << " [" << c.unit << "]";
  }
  EXPECT_EQ(all[0].name, "t_s");  // the time comes first: MCAP log times, CSV rows
  EXPECT_EQ(all[telemetry_channel_index("measured_x_m")].unit, "m");
  EXPECT_EQ(all[telemetry_channel_index("grip_force_N")].unit, "N");
  EXPECT_EQ(all[telemetry_channel_index("measured_theta_rad")].unit, "rad");
  EXPECT_EQ(all[telemetry_channel_index("deadman")].unit, "");
  EXPECT_THROW(telemetry_channel_index("no_such_m"), InvalidParams);
}

TEST(TelemetrySchema, UnitSuffixes) {
  EXPECT_EQ(telemetry_unit_suffix("m/s"), "_m_s");
  EXPECT_EQ(telemetry_unit_suffix("us"), "_us");
  EXPECT_EQ(telemetry_unit_suffix("N"), "_N");
  EXPECT_EQ(telemetry_unit_suffix(""), "");
}

TEST(TelemetrySchema, AddRefusesWhatAColumnCannotBe) {
  TelemetrySchema s;
  EXPECT_EQ(s.add({"probe_m", "m", "a probe"}), 0u);
  EXPECT_EQ(s.add({"probe_speed_m_s", "m/s", "its speed"}), 1u);
  EXPECT_EQ(s.add({"probe_on", "", "a flag"}), 2u);
  EXPECT_EQ(s.index("probe_speed_m_s"), 1u);
  EXPECT_FALSE(s.find("other_m"));
  EXPECT_THROW(s.add({"probe_m", "m", "twice"}), InvalidParams);
  EXPECT_THROW(s.add({"", "", "no name"}), InvalidParams);
  EXPECT_THROW(s.add({"probe_x", "m", "no unit suffix"}), InvalidParams);
  EXPECT_THROW(s.add({"_m", "m", "only a unit"}), InvalidParams);
  EXPECT_THROW(s.add({"Probe_y_m", "m", "a capital"}), InvalidParams);
  EXPECT_THROW(s.add({"probe y_m", "m", "a space"}), InvalidParams);
  EXPECT_THROW(s.add({"probe_V", "", "a unit suffix without a unit"}), InvalidParams);
  EXPECT_EQ(s.size(), 3u);  // nothing refused was added
  try {
    s.add({"probe_x", "m", ""});
    FAIL();
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("probe_x"), std::string::npos) << e.what();
  }
  for (std::size_t i = s.size(); i < kMaxTelemetryChannels; ++i)
    s.add({"c" + std::to_string(i) + "_V", "V", "fill"});
  EXPECT_THROW(s.add({"one_more_V", "V", "over"}), InvalidParams);
}

}  // namespace
}  // namespace mc::platform
