#include "microcobot/dsp/signals.h"

#include <cmath>
#include <cstdio>
#include <numeric>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "reference.h"

namespace mc::dsp {
namespace {

std::string fnv1a64(const std::vector<std::uint8_t>& bytes) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (std::uint8_t b : bytes) h = (h ^ b) * 0x100000001b3ULL;
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}

TEST(MaxLenSeq, IdenticalToScipyForAllBitsUpTo20) {
  const auto ref = mc::test::load_reference("dsp_mls.json");
  ASSERT_EQ(ref.at("cases").size(), 19u);
  for (const auto& c : ref.at("cases")) {
    const int nbits = c.at("nbits");
    const auto seq = max_len_seq(nbits);
    ASSERT_EQ(seq.size(), c.at("length").get<std::size_t>()) << nbits;
    EXPECT_EQ(std::accumulate(seq.begin(), seq.end(), std::size_t{0}), c.at("ones").get<std::size_t>());
    EXPECT_EQ(fnv1a64(seq), c.at("fnv1a64").get<std::string>()) << nbits;
    if (c.contains("seq")) {
      std::string text;
      for (auto b : seq) text += static_cast<char>('0' + b);
      EXPECT_EQ(text, c.at("seq").get<std::string>()) << nbits;
    }
  }
}

TEST(MaxLenSeq, MaximalForEveryTapSetUpTo32) {
  // A maximal sequence has 2^(n-1) ones per period; and its periodic autocorrelation is
  // two-valued. Checked here on the period for n <= 22 and on the first 2^16 bits beyond.
  for (int n = 2; n <= 22; ++n) {
    const auto seq = max_len_seq(n);
    EXPECT_EQ(std::accumulate(seq.begin(), seq.end(), std::size_t{0}), std::size_t{1} << (n - 1)) << n;
  }
  const auto s = max_len_seq(10);
  const std::size_t period = s.size();
  for (std::size_t lag = 1; lag < 40; ++lag) {
    long corr = 0;
    for (std::size_t i = 0; i < period; ++i) corr += (s[i] ? 1 : -1) * (s[(i + lag) % period] ? 1 : -1);
    EXPECT_EQ(corr, -1) << lag;
  }
  for (int n = 23; n <= 32; ++n) EXPECT_EQ(max_len_seq(n, 1000).size(), 1000u);
  EXPECT_THROW(max_len_seq(1), InvalidParams);
  EXPECT_THROW(max_len_seq(33), InvalidParams);
}

TEST(Prbs, HoldsEachBitForTheDividerAndRepeats) {
  const auto bits = max_len_seq(5);
  const auto u = prbs(5, 200, 3, 2.5);
  ASSERT_EQ(u.size(), 200u);
  for (std::size_t k = 0; k < u.size(); ++k) EXPECT_EQ(u[k], bits[(k / 3) % 31] ? 2.5 : -2.5) << k;
}

TEST(Sawtooth, ForwardRisesSlowlyBackwardRisesFast) {
  const double fs = 1000.0, f = 10.0;  // 100 samples per period
  const auto fwd = sawtooth(100, f, fs, 1.0, 0.9);
  const auto bwd = sawtooth(100, f, fs, 1.0, 0.1);
  EXPECT_DOUBLE_EQ(fwd[0], -1.0);
  EXPECT_NEAR(fwd[45], 0.0, 1e-12);  // halfway up the rise at 0.45 period
  EXPECT_NEAR(fwd[90], 1.0, 1e-12);  // top at 0.9 period
  EXPECT_NEAR(fwd[95], 0.0, 1e-12);  // fast drop
  EXPECT_NEAR(bwd[5], 0.0, 1e-12);   // fast rise
  EXPECT_NEAR(bwd[55], 0.0, 1e-12);  // slow fall from 0.1 to 1.0 period
  EXPECT_NEAR(sawtooth_value(-0.5 * std::numbers::pi, 0.5), sawtooth_value(1.5 * std::numbers::pi, 0.5),
              1e-15);
  EXPECT_THROW(sawtooth(10, f, fs, 1.0, 1.5), InvalidParams);
}

TEST(Signals, SineSweepNoiseStep) {
  const auto s = sine(1000, 50.0, 1000.0, 2.0, 0.0);
  EXPECT_NEAR(s[5], 2.0, 1e-12);  // quarter period
  const auto sw = log_sweep(10.0, 1000.0, 1.0, 10000.0);
  EXPECT_EQ(sw.size(), 10001u);
  EXPECT_DOUBLE_EQ(sw[0], 1.0);
  // Instantaneous frequency at t = T/2 is sqrt(f0 f1) = 100 Hz: zero crossings ~10 ms apart.
  std::vector<double> crossings;
  for (std::size_t k = 4900; k < 5200; ++k) {
    if (sw[k] <= 0 && sw[k + 1] > 0) crossings.push_back(static_cast<double>(k));
  }
  ASSERT_GE(crossings.size(), 2u);
  EXPECT_NEAR((crossings[1] - crossings[0]) / 10000.0, 0.01, 0.0005);
  const auto n = white_noise(100000, 0.5, 7);
  double m = 0, v = 0;
  for (double x : n) m += x;
  m /= static_cast<double>(n.size());
  for (double x : n) v += (x - m) * (x - m);
  EXPECT_NEAR(std::sqrt(v / static_cast<double>(n.size())), 0.5, 0.005);
  EXPECT_EQ(white_noise(10, 1.0, 7), white_noise(10, 1.0, 7));
  const auto st = step_signal(10, 100.0, 0.05, 3.0);
  EXPECT_EQ(st[4], 0.0);
  EXPECT_EQ(st[5], 3.0);
}

}  // namespace
}  // namespace mc::dsp
