// The `tweezers` command group as a user runs it.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/test_support.h"

namespace {

using mc::test::run_cli;

TEST(TweezersCli, IdentifyJsonAndArtifacts) {
  mc::test::TempDir dir;
  const auto r = run_cli({"tweezers", "identify", "--json", "--out", dir.path().string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["mode_Hz"].get<double>(), 150, 10);
  EXPECT_NEAR(j["antiresonance_Hz"].get<double>(), 390, 20);
  EXPECT_GE(j["bandwidth_Hz"].get<double>(), 100);
  EXPECT_TRUE(std::filesystem::exists(dir / "frf.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / "index.html"));
  EXPECT_NE(mc::test::read_text(dir / "frf.csv").find("f_Hz,magnitude_dB"), std::string::npos);
}

TEST(TweezersCli, VirtualCubeAndSweep) {
  auto r = run_cli({"tweezers", "virtual-cube", "--stiffness", "16000", "--no-compensator", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(nlohmann::json::parse(r.out)["chatter"].get<bool>());
  r = run_cli({"tweezers", "virtual-cube", "--stiffness", "16000", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_FALSE(j["chatter"].get<bool>());
  EXPECT_GT(j["max_penetration_m"].get<double>(), 0.0);
  r = run_cli({"tweezers", "virtual-cube", "--sweep", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_GE(j["max_stiffness_N_m"]["compensated"].get<double>(),
            2 * j["max_stiffness_N_m"]["uncompensated"].get<double>());
  EXPECT_GT(j["passivity_bound_N_m"].get<double>(), 0.0);
  EXPECT_EQ(run_cli({"tweezers", "virtual-cube", "--stiffness", "-3"}).exit_code, 2);
}

TEST(TweezersCli, ParamsRoundTripAndErrors) {
  mc::test::TempDir dir;
  auto r = run_cli({"tweezers", "params", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_DOUBLE_EQ(j["model"]["clamping_stiffness_N_per_m"].get<double>(), 190.0);
  mc::test::write_text(dir / "p.yaml", "manual:\n  set_force_N: 0.5\n");
  r = run_cli({"tweezers", "manual", "--json", "--params", (dir / "p.yaml").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NEAR(nlohmann::json::parse(r.out)["held_force_N"].get<double>(), 0.5, 0.02);
  mc::test::write_text(dir / "bad.yaml", "model:\n  lead_m: -1\n");
  EXPECT_EQ(run_cli({"tweezers", "identify", "--params", (dir / "bad.yaml").string()}).exit_code, 3);
  r = run_cli({"tweezers", "robotic", "--json", "--out", dir.path().string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir / "robotic.csv"));
}

}  // namespace
