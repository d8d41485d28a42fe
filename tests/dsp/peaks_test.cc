#include "microcobot/dsp/peaks.h"

#include <cmath>

#include <gtest/gtest.h>

#include "microcobot/dsp/signals.h"
#include "microcobot/dsp/welch.h"

namespace mc::dsp {
namespace {

TEST(FindPeaks, LocatesTonesBetterThanTheBinWidth) {
  const double fs = 10000.0;
  for (double f0 : {595.3, 1633.7, 2222.2}) {
    auto x = sine(1 << 16, f0, fs, 1.0, 0.3);
    const auto noise = white_noise(x.size(), 0.01, 3);
    for (std::size_t i = 0; i < x.size(); ++i) x[i] += noise[i];
    WelchOptions o;
    o.fs_Hz = fs;
    o.nperseg = 1024;  // bin width 9.77 Hz
    const auto p = welch(x, o);
    PeakOptions po;
    po.log_interpolation = true;
    po.max_peaks = 1;
    const auto peaks = find_peaks_xy(p.f_Hz, p.value, po);
    ASSERT_EQ(peaks.size(), 1u);
    const double bin = p.f_Hz[1] - p.f_Hz[0];
    EXPECT_LT(std::abs(peaks[0].x - f0), 0.1 * bin) << f0;
    EXPECT_GT(std::abs(p.f_Hz[peaks[0].index] - f0), std::abs(peaks[0].x - f0) - 1e-12);
  }
}

TEST(FindPeaks, HeightProminenceDistancePlateau) {
  const std::vector<double> y{0, 1, 0, 5, 5, 5, 0, 2, 1.5, 3, 0, 0.5};
  auto all = find_peaks(y);
  ASSERT_EQ(all.size(), 4u);
  EXPECT_EQ(all[0].index, 1u);
  EXPECT_EQ(all[1].index, 4u);  // plateau middle
  EXPECT_EQ(all[2].index, 7u);
  EXPECT_EQ(all[3].index, 9u);
  EXPECT_DOUBLE_EQ(all[2].prominence, 0.5);
  EXPECT_DOUBLE_EQ(all[3].prominence, 3.0);
  PeakOptions o;
  o.min_height = 2.5;
  EXPECT_EQ(find_peaks(y, o).size(), 2u);
  o = {};
  o.min_prominence = 1.0;
  EXPECT_EQ(find_peaks(y, o).size(), 3u);
  o = {};
  o.min_distance = 4;
  const auto d = find_peaks(y, o);  // 4 beats 1 and 7 (3 apart); 9 survives (5 from 4)
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0].index, 4u);
  EXPECT_EQ(d[1].index, 9u);
}

TEST(FindPeaks, ParabolaIsExactOnAParabola) {
  std::vector<double> y;
  for (int i = 0; i < 11; ++i) y.push_back(4.0 - (i - 5.3) * (i - 5.3));
  const auto p = find_peaks(y);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_NEAR(p[0].position, 5.3, 1e-12);
  EXPECT_NEAR(p[0].height, 4.0, 1e-12);
}

}  // namespace
}  // namespace mc::dsp
