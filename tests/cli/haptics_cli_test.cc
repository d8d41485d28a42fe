// The `haptics` command group as a user runs it: exit codes, --json fields, artifacts, and
// one-line errors for bad flags and bad --params files.

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/test_support.h"

namespace mc {
namespace {

using test::line_count;
using test::run_cli;
using ::testing::HasSubstr;

TEST(HapticsCli, HelpListsTheVerbs) {
  const auto r = run_cli({"haptics", "--help"});
  EXPECT_EQ(r.exit_code, 0);
  for (const char* verb : {"params", "identify", "evaluate", "tweezers"}) EXPECT_THAT(r.out, HasSubstr(verb));
}

TEST(HapticsCli, ParamsPrintsThePlantPipelineAndTrapKeys) {
  const auto r = run_cli({"haptics", "params", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_DOUBLE_EQ(j["pipeline"]["cutoff_Hz"].get<double>(), 200.0);
  EXPECT_DOUBLE_EQ(j["pipeline"]["fs_Hz"].get<double>(), 1.0e4);
  EXPECT_TRUE(j["plant"].contains("m_h_kg"));
  EXPECT_DOUBLE_EQ(j["trap"]["bead_radius_m"].get<double>(), 1.5e-6);
  // A file with the printed keys is accepted and its values used.
  test::TempDir dir;
  test::write_text(dir / "p.yaml", "trap:\n  trap_stiffness_N_per_m: 2.0e-5\n");
  const auto r2 = run_cli({"haptics", "params", "--json", "--params", (dir / "p.yaml").string()});
  ASSERT_EQ(r2.exit_code, 0) << r2.err;
  EXPECT_DOUBLE_EQ(nlohmann::json::parse(r2.out)["trap"]["trap_stiffness_N_per_m"].get<double>(), 2.0e-5);
}

TEST(HapticsCli, IdentifyJsonAndArtifacts) {
  test::TempDir dir;
  const auto r = run_cli({"haptics", "identify", "--json", "--out", dir.path().string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_DOUBLE_EQ(j["cutoff_Hz"].get<double>(), 200.0);  // §3.4.2
  EXPECT_GT(j["lf_gain"].get<double>(), 0.0);
  ASSERT_EQ(j["hf_num"].size(), 2u);
  ASSERT_EQ(j["hf_den"].size(), 3u);
  EXPECT_DOUBLE_EQ(j["hf_den"][0].get<double>(), 1.0);  // monic
  for (const auto& c : j["hf_num"]) EXPECT_GT(c.get<double>(), 0.0);
  for (const auto& c : j["hf_den"]) EXPECT_GT(c.get<double>(), 0.0);
  EXPECT_LT(j["hf_valid_lower_Hz"].get<double>(), j["cutoff_Hz"].get<double>());
  EXPECT_GT(j["hf_delay_s"].get<double>(), 0.0);  // the high band is aligned to the low one
  EXPECT_GT(j["lf_flat_upper_Hz"].get<double>(), j["cutoff_Hz"].get<double>());
  for (const char* f : {"frf_lf.csv", "frf_hf.csv", "index.html"})
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  EXPECT_THAT(test::read_text(dir / "frf_hf.csv"), HasSubstr("f_Hz,mag_dB,phase_deg,coherence"));
}

TEST(HapticsCli, EvaluateIsFlatOverTheThirdOctaves) {
  test::TempDir dir;
  const auto r = run_cli({"haptics", "evaluate", "--json", "--out", dir.path().string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["fc_Hz"].size(), 14u);  // Table 3.4: 63 Hz .. 1.25 kHz
  EXPECT_NEAR(j["fc_Hz"][0].get<double>(), 1000.0 * std::pow(10.0, -1.2), 1e-9);
  for (const char* k : {"lf_dB", "hf_dB", "combined_dB", "pantograph_dB"}) EXPECT_EQ(j[k].size(), 14u) << k;
  EXPECT_LT(j["flatness_dB"].get<double>(), 1.0);
  for (const auto& v : j["combined_dB"]) EXPECT_LT(std::abs(v.get<double>()), 0.5);  // goal +-0.5 dB
  EXPECT_DOUBLE_EQ(j["cutoff_Hz"].get<double>(), 200.0);
  EXPECT_THAT(test::read_text(dir / "evaluation.csv"),
              HasSubstr("fc_Hz,lf_dB,hf_dB,combined_dB,pantograph_dB"));
}

TEST(HapticsCli, TweezersBrownianAndContact) {
  auto r = run_cli({"haptics", "tweezers", "--scenario", "brownian", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["scenario"], "brownian");
  EXPECT_GE(j["r2"].get<double>(), 0.98);              // Fig. 3.15
  EXPECT_NEAR(j["kurtosis"].get<double>(), 3.0, 0.3);  // Gaussian
  EXPECT_NEAR(j["corner_Hz"].get<double>() / j["expected_corner_Hz"].get<double>(), 1.0, 0.05);
  EXPECT_FALSE(j.contains("contact_time_s"));
  test::TempDir dir;
  r = run_cli({"haptics", "tweezers", "--scenario", "contact", "--duration", "1", "--json", "--out",
               dir.path().string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  const double tc = j["contact_time_s"].get<double>();
  EXPECT_NEAR(tc, 0.5, 0.03);                           // 2 um gap at 4 um/s
  EXPECT_GT(j["force_peak_time_s"].get<double>(), tc);  // Fig. 3.16: the peak follows the contact
  EXPECT_THAT(test::read_text(dir / "tweezers.csv"),
              HasSubstr("t_s,bead_y_m,trap_y_m,force_y_N,hand_force_N,accel_m_s2"));
  EXPECT_TRUE(std::filesystem::exists(dir / "index.html"));
}

TEST(HapticsCli, UsageErrorsExitTwoWithOneLine) {
  for (const auto& args :
       std::vector<std::vector<std::string>>{{"haptics", "identify", "--bogus"},
                                             {"haptics", "evaluate", "--out"},
                                             {"haptics", "tweezers", "--scenario", "sideways"},
                                             {"haptics", "tweezers", "--duration", "0.1"},
                                             {"haptics", "no-such-verb"}}) {
    const auto r = run_cli(args);
    EXPECT_EQ(r.exit_code, 2) << args.back();
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
    EXPECT_THAT(r.err, HasSubstr("microcobot: error:"));
    EXPECT_EQ(r.out, "");
  }
}

TEST(HapticsCli, BadParamsExitThreeWithOneLineNamingTheProblem) {
  test::TempDir dir;
  struct Case {
    std::string yaml;
    std::string expect;  // after the file name: ":line: what"
  };
  const std::vector<Case> cases = {
      {"pipeline:\n  cutoff_Hz: 200\n  - 300\n", ":3: malformed YAML"},  // a list item inside a map
      {"plant:\n  m_h_kg: 0.02\n  mass_kg: 1\n", ":3: unknown key 'plant.mass_kg'"},
      {"trap:\n  trap_stiffness_N_per_m: stiff\n",
       ":2: 'trap.trap_stiffness_N_per_m' must be"},  // wrong type
  };
  for (const auto& verb : {"identify", "evaluate", "tweezers"}) {
    for (std::size_t i = 0; i < cases.size(); ++i) {
      const auto file = dir / ("bad" + std::to_string(i) + ".yaml");
      test::write_text(file, cases[i].yaml);
      const auto r = run_cli({"haptics", verb, "--json", "--params", file.string()});
      EXPECT_EQ(r.exit_code, 3) << verb << " " << cases[i].yaml;
      EXPECT_EQ(line_count(r.err), 1u) << r.err;
      EXPECT_THAT(r.err, HasSubstr(file.string() + cases[i].expect));
      EXPECT_EQ(r.out, "");
    }
  }
  // Out of range: the file and the full key of the parameter, with its constraint.
  test::write_text(dir / "range.yaml", "pipeline:\n  cutoff_Hz: 6000\n");
  auto r = run_cli({"haptics", "identify", "--params", (dir / "range.yaml").string()});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(line_count(r.err), 1u) << r.err;
  EXPECT_THAT(r.err, HasSubstr((dir / "range.yaml").string() +
                               ": invalid parameter pipeline.cutoff_Hz: must be in (0, fs/2) (got 6000)"));
  test::write_text(dir / "range.yaml", "plant:\n  m_h_kg: -1\n");
  r = run_cli({"haptics", "evaluate", "--params", (dir / "range.yaml").string()});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_THAT(r.err, HasSubstr((dir / "range.yaml").string() + ": invalid parameter plant.m_h_kg: must be"));
  // A missing file is invalid input naming it.
  r = run_cli({"haptics", "tweezers", "--params", (dir / "missing.yaml").string()});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(line_count(r.err), 1u) << r.err;
  EXPECT_THAT(r.err, HasSubstr("missing.yaml"));
}

}  // namespace
}  // namespace mc
