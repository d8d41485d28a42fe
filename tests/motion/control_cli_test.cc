// `microcobot control ...`: JSON contracts and bad flags.
#include <algorithm>
#include <string>
#include <vector>

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

TEST(ControlCli, LearnPrintsPerTrialFiguresAndRefusesBadFlags) {
  const auto r = mc::test::run_cli({"control", "learn", "--case", "trapezoid00", "--trials", "3", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["set"], "validation");
  EXPECT_EQ(j["seed"], 31);
  ASSERT_EQ(j["references"].size(), 1u);
  const auto& trials = j["references"][0]["trials"];
  ASSERT_EQ(trials.size(), 3u);
  for (const auto& t : trials) {
    EXPECT_GT(t["rms_error_m"].get<double>(), 0.0);
    EXPECT_GE(t["max_error_m"].get<double>(), t["rms_error_m"].get<double>());
  }
  EXPECT_EQ(trials[0]["correction_max_m"].get<double>(), 0.0);  // the first trial runs uncorrected
  EXPECT_GT(trials[2]["correction_max_m"].get<double>(), 0.0);
  EXPECT_EQ(j["summary"]["per_trial"].size(), 3u);
  EXPECT_EQ(j["learning"]["learning_gain"], 0.6);
  // Usage errors exit 2, one line; a parameter out of its range exits 3 naming the flag.
  for (const auto& bad : std::vector<std::vector<std::string>>{{"--trials", "0"},
                                                               {"--case", "nope"},
                                                               {"--gain", "nan"},
                                                               {"--case", "trapezoid00", "--references", "2"},
                                                               {"--set", "nope"}}) {
    std::vector<std::string> args{"control", "learn"};
    args.insert(args.end(), bad.begin(), bad.end());
    const auto e = mc::test::run_cli(args);
    EXPECT_EQ(e.exit_code, 2) << bad[0];
    EXPECT_EQ(std::count(e.err.begin(), e.err.end(), '\n'), 1) << e.err;
  }
  const auto g = mc::test::run_cli({"control", "learn", "--gain", "2"});
  EXPECT_EQ(g.exit_code, 3);
  EXPECT_NE(g.err.find("--gain"), std::string::npos) << g.err;
  EXPECT_EQ(mc::test::run_cli({"control", "learn", "--seed", "15"}).exit_code, 3);  // the tuning seed
}

}  // namespace
