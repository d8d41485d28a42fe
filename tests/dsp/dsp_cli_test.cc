// `microcobot dsp` end to end: the CLI computes what the library computes.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fmt/format.h>
#include "microcobot/dsp/butterworth.h"
#include "microcobot/dsp/lti.h"
#include "support/test_support.h"

namespace {

TEST(DspCli, ButterMlsAndErrors) {
  auto r = mc::test::run_cli({"dsp", "butter", "--order", "3", "--fc", "1000", "--fs", "48000", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const auto sos = mc::dsp::butter(3, 1000, 48000, mc::dsp::FilterType::kLowPass);
  ASSERT_EQ(j.at("sos").size(), sos.size());
  EXPECT_DOUBLE_EQ(j.at("sos")[0][0].get<double>(), sos[0].b0);
  r = mc::test::run_cli({"dsp", "mls", "--bits", "4", "--json"});
  ASSERT_EQ(r.exit_code, 0);
  EXPECT_EQ(nlohmann::json::parse(r.out).at("seq").get<std::vector<int>>(),
            (std::vector<int>{1, 1, 1, 1, 0, 1, 0, 1, 1, 0, 0, 1, 0, 0, 0}));  // scipy's docstring
  EXPECT_EQ(mc::test::run_cli({"dsp", "butter", "--fc", "6000", "--fs", "10000"}).exit_code, 3);
  EXPECT_EQ(mc::test::run_cli({"dsp", "butter", "--fc", "-1", "--fs", "10000"}).exit_code, 2);
}

TEST(DspCli, TffitAndOctaveFromAnFrfFile) {
  const mc::dsp::TransferFunction g({250.0, 6.406e5}, {1.0, 2135.0, 4.559e6});
  mc::test::TempDir dir;
  std::string csv = "f_Hz,re,im\n";
  for (double f = 100; f <= 1000; f += 10) {
    const auto h = g.response(2 * std::numbers::pi * f);
    csv += std::to_string(f) + "," + fmt::format("{:.17g},{:.17g}\n", h.real(), h.imag());
  }
  mc::test::write_text(dir / "frf.csv", csv);
  auto r = mc::test::run_cli(
      {"dsp", "tffit", "--in", (dir / "frf.csv").string(), "--nz", "1", "--np", "2", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j.at("den")[2].get<double>(), 4.559e6, 1e-6 * 4.559e6);
  EXPECT_NEAR(j.at("num")[0].get<double>(), 250.0, 1e-6 * 250.0);
  r = mc::test::run_cli({"dsp", "octave", "--in", (dir / "frf.csv").string(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out).at("fc_Hz").size(), 11u);
}

}  // namespace
