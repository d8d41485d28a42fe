#include "microcobot/dsp/butterworth.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "reference.h"

namespace mc::dsp {
namespace {

TEST(Butterworth, MatchesScipySectionBySection) {
  const auto ref = mc::test::load_reference("dsp_butter.json");
  ASSERT_GE(ref.at("cases").size(), 10u);
  for (const auto& c : ref.at("cases")) {
    const int order = c.at("order");
    const double fc = c.at("fc"), fs = c.at("fs");
    const auto type = parse_filter_type(c.at("type"));
    const Sos sos =
        c.at("kind") == "butter" ? butter(order, fc, fs, type) : linkwitz_riley(order, fc, fs, type);
    const auto& rows = c.at("sos");
    ASSERT_EQ(sos.size(), rows.size()) << c.dump();
    double scale = 0.0;  // relative to the largest coefficient of the row
    for (std::size_t i = 0; i < sos.size(); ++i) {
      const auto row = sos[i].row();
      for (int j = 0; j < 6; ++j) scale = std::max(scale, std::abs(rows[i][j].get<double>()));
      for (int j = 0; j < 6; ++j) {
        const double want = rows[i][j];
        EXPECT_NEAR(row[static_cast<std::size_t>(j)], want, 1e-10 * std::max(std::abs(want), 1e-3 * scale))
            << c.at("kind") << " order " << order << " fc " << fc << " section " << i << " coef " << j;
      }
    }
  }
}

TEST(Butterworth, MinusThreeDecibelsAtCutoffAndUnitPassband) {
  for (int order = 1; order <= 8; ++order) {
    const auto lp = butter(order, 200.0, 10000.0, FilterType::kLowPass);
    const auto hp = butter(order, 200.0, 10000.0, FilterType::kHighPass);
    EXPECT_NEAR(std::abs(sos_response(lp, 200.0, 10000.0)), std::sqrt(0.5), 1e-12);
    EXPECT_NEAR(std::abs(sos_response(hp, 200.0, 10000.0)), std::sqrt(0.5), 1e-12);
    EXPECT_NEAR(std::abs(sos_response(lp, 0.0, 10000.0)), 1.0, 1e-12);
    EXPECT_NEAR(std::abs(sos_response(hp, 5000.0, 10000.0)), 1.0, 1e-12);
    // Roll-off of 20*order dB per decade well above the cut-off (still far below Nyquist).
    const double ratio =
        std::abs(sos_response(lp, 2000.0, 10000.0)) / std::abs(sos_response(lp, 1000.0, 10000.0));
    EXPECT_LT(ratio, std::pow(0.5, order) * 1.2) << order;
  }
}

TEST(LinkwitzRiley, Lr4PairSumsToAllPass) {
  for (double fc : {200.0, 1000.0, 10000.0}) {
    const double fs = 50000.0;
    const auto x = linkwitz_riley_crossover(4, fc, fs);
    for (double f = 1.0; f < fs / 2; f *= 1.07) {
      const auto lp = sos_response(x.low, f, fs), hp = sos_response(x.high, f, fs);
      EXPECT_NEAR(std::abs(lp + hp), 1.0, 1e-12) << "fc " << fc << " f " << f;
    }
    // -6 dB each at the cut-off, in phase with each other there.
    EXPECT_NEAR(std::abs(sos_response(x.low, fc, fs)), 0.5, 1e-12);
    EXPECT_NEAR(std::abs(sos_response(x.high, fc, fs)), 0.5, 1e-12);
  }
}

TEST(LinkwitzRiley, AnalogLr4IsAllPassAndLr2NeedsInversion) {
  const double wc = 2 * std::numbers::pi * 200.0;
  const auto lp4 = linkwitz_riley_analog(4, wc, FilterType::kLowPass);
  const auto hp4 = linkwitz_riley_analog(4, wc, FilterType::kHighPass);
  const auto lp2 = linkwitz_riley_analog(2, wc, FilterType::kLowPass);
  const auto hp2 = linkwitz_riley_analog(2, wc, FilterType::kHighPass);
  for (double w = 1.0; w < 1e6; w *= 1.3) {
    EXPECT_NEAR(std::abs(zpk_response_analog(lp4, w) + zpk_response_analog(hp4, w)), 1.0, 1e-12);
    EXPECT_NEAR(std::abs(zpk_response_analog(lp2, w) - zpk_response_analog(hp2, w)), 1.0, 1e-12);
  }
  // LR2 summed without inversion has a notch at the cut-off.
  EXPECT_LT(std::abs(zpk_response_analog(lp2, wc) + zpk_response_analog(hp2, wc)), 1e-12);
}

TEST(Butterworth, RejectsBadDesigns) {
  EXPECT_THROW(butter(0, 100.0, 1000.0, FilterType::kLowPass), InvalidParams);
  EXPECT_THROW(butter(21, 100.0, 1000.0, FilterType::kLowPass), InvalidParams);
  EXPECT_THROW(butter(2, 500.0, 1000.0, FilterType::kLowPass), InvalidParams);
  EXPECT_THROW(butter(2, -1.0, 1000.0, FilterType::kLowPass), InvalidParams);
  EXPECT_THROW(linkwitz_riley(3, 100.0, 1000.0, FilterType::kLowPass), InvalidParams);
  EXPECT_THROW(parse_filter_type("band"), UsageError);
}

}  // namespace
}  // namespace mc::dsp
