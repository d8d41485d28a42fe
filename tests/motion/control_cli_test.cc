// `microcobot control ...`: JSON contracts and bad flags.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/test_support.h"

namespace {

TEST(ControlCli, VelocityPrintsTheIssueKeys) {
  const auto r = mc::test::run_cli({"control", "velocity", "--reference", "1e-4", "--direction", "backward",
                                    "--duration", "0.2", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* k : {"mean_velocity_m_s", "steady_state_error_rel", "settling_time_s", "ripple_m_s"}) {
    EXPECT_TRUE(j.contains(k)) << k;
  }
  EXPECT_LT(j["mean_velocity_m_s"].get<double>(), 0.0);
  EXPECT_TRUE(j["baselines"].contains("pid"));
}

TEST(ControlCli, PositionAndTrajectoryPrintTheIssueKeys) {
  mc::test::TempDir dir;
  auto r = mc::test::run_cli({"control", "position", "--target", "2e-6", "--start", "0", "--axis", "y",
                              "--json", "--out", dir.path().string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_LE(j["final_error_m"].get<double>(), 5e-9);
  EXPECT_TRUE(j.contains("overshoot_m"));
  EXPECT_TRUE(j.contains("move_time_s"));
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "position.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "index.html"));
  r = mc::test::run_cli({"control", "trajectory", "--profile", "trapezoid", "--distance", "2e-5", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_GT(j["max_error_m"].get<double>(), j["rms_error_m"].get<double>());
}

TEST(ControlCli, BadFlagsExit2) {
  EXPECT_EQ(mc::test::run_cli({"control", "velocity", "--direction", "sideways"}).exit_code, 2);
  EXPECT_EQ(mc::test::run_cli({"control", "position", "--target", "1", "--json"}).exit_code, 2);
  EXPECT_EQ(mc::test::run_cli({"control", "position", "--target", "0", "--axis", "w"}).exit_code, 2);
  EXPECT_EQ(mc::test::run_cli({"control", "trajectory", "--profile", "zigzag"}).exit_code, 2);
}

}  // namespace
