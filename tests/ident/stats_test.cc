#include "microcobot/ident/stats.h"

#include <gtest/gtest.h>

#include "../dsp/reference.h"
#include "microcobot/core/error.h"
#include "microcobot/dsp/signals.h"

namespace mc::ident {
namespace {

TEST(Stats, MatchScipyOnGammaData) {
  const auto ref = mc::test::load_reference("dsp_stats.json");
  const auto x = ref.at("x").get<std::vector<double>>();
  EXPECT_NEAR(mean(x), ref.at("mean").get<double>(), 1e-12);
  EXPECT_NEAR(stddev(x), ref.at("std").get<double>(), 1e-12);
  EXPECT_NEAR(rms(x), ref.at("rms").get<double>(), 1e-12);
  EXPECT_NEAR(skewness(x), ref.at("skewness").get<double>(), 1e-12);
  EXPECT_NEAR(kurtosis(x), ref.at("kurtosis").get<double>(), 1e-12);
}

TEST(Stats, GaussianFitOfAGaussianHistogram) {
  auto x = dsp::white_noise(100000, 2.0, 9);
  for (double& v : x) v += 5.0;
  const auto h = histogram(x, 60, -3.0, 13.0);
  const auto g = fit_gaussian(h.centres, h.counts);
  EXPECT_NEAR(g.mean, 5.0, 0.03);
  EXPECT_NEAR(g.sigma, 2.0, 0.03);
  EXPECT_NEAR(g.amplitude, 100000 * h.width / (2.0 * std::sqrt(2 * std::numbers::pi)),
              0.02 * 100000 * h.width / 5.0);
  EXPECT_GT(g.r2, 0.995);
  EXPECT_NEAR(kurtosis(x), 0.0, 0.05);
  EXPECT_NEAR(skewness(x), 0.0, 0.05);
  // A uniform histogram is a poor Gaussian.
  std::vector<double> flat(40, 10.0), centres(40);
  for (std::size_t i = 0; i < 40; ++i) centres[i] = static_cast<double>(i);
  flat[0] = flat[39] = 0.0;
  EXPECT_LT(fit_gaussian(centres, flat).r2, 0.9);
}

TEST(Stats, Errors) {
  EXPECT_THROW(mean(std::vector<double>{}), InvalidParams);
  EXPECT_THROW(skewness(std::vector<double>{1, 1, 1}), ComputationFailed);
  EXPECT_THROW(fit_gaussian(std::vector<double>{1, 2}, std::vector<double>{1, 2}), InvalidParams);
}

}  // namespace
}  // namespace mc::ident
