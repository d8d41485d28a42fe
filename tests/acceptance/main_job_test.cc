// The main job end to end: the default pick-and-place through `microcobot run`
// and the stale-master scenario through the library. About 10 s each in release; labelled
// slow (not run under the sanitizers).

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>

#include "microcobot/cell/session.h"
#include "microcobot/core/csv.h"
#include "support/test_support.h"

namespace mc {
namespace {

TEST(MainJob, TheDefaultPickAndPlacePlacesThePartWithinFiveMicrometres) {
  test::TempDir dir;
  const auto r = test::run_cli({"run", "--json", "--out", dir.path().string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["success"].get<bool>());
  EXPECT_LT(j["placement_error_m"].get<double>(), 5e-6);
  EXPECT_GT(j["ticks"].get<std::uint64_t>(), 200000u);  // > 20 s at 10 kHz
  EXPECT_TRUE(j.contains("overruns"));
  EXPECT_GT(j["tick_p99_us"].get<double>(), 0.0);
  EXPECT_GE(j["clutches"].get<int>(), 2);  // 200 mm of hand motion needs indexing
  EXPECT_TRUE(std::filesystem::exists(dir / "index.html"));

  // The part travelled 2 mm at the transport speed: 100 um/s while carried and engaged.
  const auto rec = read_csv(dir / "recording.csv");
  const auto& t = rec.column("t_s");
  const auto& x = rec.column("part_x_m");
  const auto& phase = rec.column("part_phase");
  const auto& engaged = rec.column("engaged");
  std::vector<double> speeds;
  for (std::size_t i = 100; i < t.size(); i += 100) {
    bool steady = true;
    for (std::size_t k = i - 100; k <= i; ++k) steady = steady && phase[k] == 1.0 && engaged[k] == 1.0;
    const double v = (x[i] - x[i - 100]) / (t[i] - t[i - 100]);
    if (steady && x[i] > 0.2e-3 && x[i] < 1.8e-3) speeds.push_back(v);
  }
  ASSERT_GT(speeds.size(), 50u);
  std::nth_element(speeds.begin(), speeds.begin() + static_cast<long>(speeds.size() / 2), speeds.end());
  EXPECT_NEAR(speeds[speeds.size() / 2], 100e-6, 10e-6);
}

TEST(MainJob, AStaleMasterMidTransportIsHeldSafelyAndTheJobStillFinishes) {
  cell::SessionParams sp;
  sp.scenario = "stale-master";
  platform::PlatformConfig config;
  cell::Session s(config, sp);
  const auto r = s.run();
  EXPECT_TRUE(r.success) << r.verdict;
  EXPECT_THAT(r.verdict, ::testing::HasSubstr("held with zero force"));
  EXPECT_LT(r.placement_error_m, 5e-6);
}

}  // namespace
}  // namespace mc
