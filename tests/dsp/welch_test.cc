#include "microcobot/dsp/welch.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/dsp/butterworth.h"
#include "microcobot/dsp/signals.h"
#include "microcobot/dsp/sos.h"
#include "reference.h"

namespace mc::dsp {
namespace {

WelchOptions options_from(const nlohmann::json& o) {
  WelchOptions w;
  w.fs_Hz = o.at("fs");
  if (o.contains("nperseg")) w.nperseg = o.at("nperseg");
  if (o.contains("noverlap")) w.noverlap = o.at("noverlap").get<std::size_t>();
  if (o.contains("nfft")) w.nfft = o.at("nfft");
  if (o.contains("detrend")) w.detrend = parse_detrend(o.at("detrend"));
  if (o.contains("scaling")) w.scaling = parse_scaling(o.at("scaling"));
  return w;
}

void expect_close(const std::vector<double>& got, const std::vector<double>& want, double rel,
                  const std::string& what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  double scale = 0;
  for (double v : want) scale = std::max(scale, std::abs(v));
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_NEAR(got[i], want[i], rel * std::max(std::abs(want[i]), 1e-6 * scale)) << what << " bin " << i;
  }
}

TEST(Welch, MatchesScipyPsdCsdCoherence) {
  const auto ref = mc::test::load_reference("dsp_welch.json");
  const auto x = ref.at("x").get<std::vector<double>>();
  const auto y = ref.at("y").get<std::vector<double>>();
  ASSERT_GE(ref.at("cases").size(), 8u);
  for (const auto& c : ref.at("cases")) {
    const auto opt = options_from(c.at("options"));
    const std::string what = c.at("options").dump();
    const auto px = welch(x, opt);
    expect_close(px.f_Hz, c.at("f").get<std::vector<double>>(), 1e-12, what + " f");
    expect_close(px.value, c.at("pxx").get<std::vector<double>>(), 1e-9, what + " pxx");
    expect_close(welch(y, opt).value, c.at("pyy").get<std::vector<double>>(), 1e-9, what + " pyy");
    const auto pxy = csd(x, y, opt);
    const auto want = mc::test::complex_vector(c.at("pxy"));
    ASSERT_EQ(pxy.value.size(), want.size());
    double scale = 0;
    for (const auto& v : want) scale = std::max(scale, std::abs(v));
    for (std::size_t i = 0; i < want.size(); ++i) {
      EXPECT_NEAR(std::abs(pxy.value[i] - want[i]), 0.0, 1e-9 * std::max(std::abs(want[i]), 1e-6 * scale))
          << what << " pxy bin " << i;
    }
    auto copt = opt;
    copt.scaling = Scaling::kDensity;
    expect_close(coherence(x, y, copt).value, c.at("cxy").get<std::vector<double>>(), 1e-9, what + " cxy");
  }
}

TEST(Welch, ParsevalForWhiteNoise) {
  // The density integrates to the variance: sigma^2 = sum(P) df.
  const auto x = white_noise(200000, 0.7, 11);
  WelchOptions o;
  o.fs_Hz = 10000.0;
  o.nperseg = 1024;
  const auto p = welch(x, o);
  double power = 0;
  for (double v : p.value) power += v * (p.f_Hz[1] - p.f_Hz[0]);
  EXPECT_NEAR(power, 0.49, 0.49 * 0.01);
}

TEST(Welch, H1RecoversAKnownFilter) {
  // Input white noise through a 2nd-order Butterworth; H1 matches the designed response.
  const double fs = 10000.0;
  const auto sos = butter(2, 500.0, fs, FilterType::kLowPass);
  const auto x = white_noise(1 << 17, 1.0, 5);
  const auto y = sosfilt(sos, x);
  WelchOptions o;
  o.fs_Hz = fs;
  o.nperseg = 1024;
  const auto h = frf_h1(x, y, o);
  for (std::size_t k = 1; k < h.f_Hz.size() && h.f_Hz[k] < 1500; ++k) {
    const auto want = sos_response(sos, h.f_Hz[k], fs);
    EXPECT_NEAR(std::abs(h.h[k] - want), 0.0, 0.01) << h.f_Hz[k];
    EXPECT_GT(h.coherence[k], 0.99);
  }
}

TEST(Welch, RejectsBadOptions) {
  std::vector<double> x(100, 1.0);
  WelchOptions o;
  o.nperseg = 64;
  o.noverlap = 64;
  EXPECT_THROW(welch(x, o), InvalidParams);
  o.noverlap = 10;
  o.nfft = 32;
  EXPECT_THROW(welch(x, o), InvalidParams);
  EXPECT_THROW(welch(std::vector<double>{}, WelchOptions{}), InvalidParams);
  EXPECT_THROW(csd(x, std::vector<double>(99), WelchOptions{}), InvalidParams);
  EXPECT_THROW(parse_detrend("linear"), UsageError);
}

// Finite data near the largest double overflow the squared spectrum; the H1 estimate
// read 0 there (Pxx = inf) instead of failing. Both estimates now fail naming the argument.
TEST(Welch, AnOverflowingSpectrumFailsNamingTheSignal) {
  std::vector<double> x(512), y(512);
  for (std::size_t i = 0; i < x.size(); ++i) {
    x[i] = std::sin(0.3 * static_cast<double>(i));
    y[i] = 1e308 * std::sin(0.3 * static_cast<double>(i) + 1.0);
  }
  WelchOptions o;
  o.fs_Hz = 1e3;
  EXPECT_NO_THROW(frf_h1(x, x, o));
  try {
    frf_h1(x, y, o);
    ADD_FAILURE() << "no overflow reported";
  } catch (const SpectrumOverflow& e) {
    EXPECT_EQ(e.signal(), "y");
    EXPECT_GT(e.max_abs(), 9e307);
  }
  try {
    welch(y, o);
    ADD_FAILURE() << "no overflow reported";
  } catch (const SpectrumOverflow& e) {
    EXPECT_EQ(e.signal(), "x");  // welch's argument
  }
  EXPECT_THROW(frf_h1(y, x, o), ComputationFailed);
}

}  // namespace
}  // namespace mc::dsp
