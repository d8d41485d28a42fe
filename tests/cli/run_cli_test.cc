// `microcobot run` as a user meets it: configuration printing, bad configuration, bad flags.
// The full session is run by tests/acceptance (label slow).

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>

#include "support/test_support.h"

namespace mc {
namespace {

using test::line_count;
using test::run_cli;
using ::testing::HasSubstr;

TEST(RunCli, PrintsTheConfigurationItAccepts) {
  const auto r = run_cli({"run", "--print-config", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_DOUBLE_EQ(j["loop"]["base_rate_Hz"].get<double>(), 1e4);
  EXPECT_DOUBLE_EQ(j["teleop"]["motion_scale"].get<double>(), 0.01);
  EXPECT_TRUE(j["world"].contains("target_x_m"));
  // What it prints is a configuration it reads back.
  test::TempDir dir;
  const auto yaml = run_cli({"run", "--print-config"});
  std::ofstream(dir / "platform.yaml") << yaml.out;
  const auto again =
      run_cli({"run", "--print-config", "--json", "--config", (dir / "platform.yaml").string()});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(nlohmann::json::parse(again.out), j);
}

TEST(RunCli, BadConfigurationExitsThreeWithOneLineNamingTheKey) {
  test::TempDir dir;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"teleop:\n  force_scal: 1\n", "force_scal"},
      {"teleop:\n  force_scale: [1, 2]\n", "force_scale"},
      {"world:\n  part_side_m: -1\n", "world.part_side_m"},
      {"loop: {base_rate_Hz: 10000\n", "platform.yaml"},
  };
  for (const auto& [yaml, named] : cases) {
    std::ofstream(dir / "platform.yaml") << yaml;
    const auto r =
        run_cli({"run", "--config", (dir / "platform.yaml").string(), "--out", (dir / "o").string()});
    EXPECT_EQ(r.exit_code, 3) << yaml;
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
    EXPECT_THAT(r.err, HasSubstr(named));
    EXPECT_FALSE(std::filesystem::exists(dir / "o"));  // nothing written
  }
}

TEST(RunCli, BadFlagsExitTwo) {
  for (const auto& args : std::vector<std::vector<std::string>>{
           {"run", "--scenario", "juggle"}, {"run", "--duration", "-1"}, {"run", "--speed", "3"}}) {
    const auto r = run_cli(args);
    EXPECT_EQ(r.exit_code, 2) << args[1];
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
  }
  // A missing configuration is invalid input, like a missing --params file.
  const auto r = run_cli({"run", "--config", "/nonexistent.yaml"});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(line_count(r.err), 1u) << r.err;
}

TEST(RunCli, AFailedScenarioExitsFourAndKeepsItsReport) {
  // One simulated second is too short for the pick-and-place: the scenario fails, and what it
  // recorded is what the user needs to see why (docs/cli.md).
  test::TempDir dir;
  const auto out = dir / "session";
  const auto r = run_cli({"run", "--duration", "1", "--json", "--out", out.string()});
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_THAT(r.err, HasSubstr("maximum duration"));
  EXPECT_EQ(line_count(r.err), 1u) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_FALSE(j.at("success").get<bool>());
  EXPECT_EQ(j.at("report").get<std::string>(), (out / "index.html").string());
  EXPECT_TRUE(std::filesystem::exists(out / "index.html"));
  EXPECT_TRUE(std::filesystem::exists(out / "recording.csv"));
  EXPECT_TRUE(std::filesystem::exists(out / "recording.mcap"));
}

}  // namespace
}  // namespace mc
