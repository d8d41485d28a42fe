#include "microcobot/dsp/octave.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"

namespace mc::dsp {
namespace {

TEST(Octave, BaseTenCentres) {
  const auto c = third_octave_centres(100.0, 1000.0);
  ASSERT_EQ(c.size(), 11u);  // 100, 125.9, ..., 1000
  EXPECT_DOUBLE_EQ(c.front(), 100.0);
  EXPECT_DOUBLE_EQ(c.back(), 1000.0);
  for (std::size_t i = 1; i < c.size(); ++i) EXPECT_NEAR(c[i] / c[i - 1], std::pow(10.0, 0.1), 1e-12);
  // The 31 audio bands, nominal 20 Hz..20 kHz, have exact centres 19.95 Hz..19.95 kHz.
  EXPECT_EQ(third_octave_centres(19.9, 20000.0).size(), 31u);
  EXPECT_EQ(third_octave_centres(20.0, 20000.0).size(), 30u);
  EXPECT_THROW(third_octave_centres(100.0, 50.0), InvalidParams);
}

TEST(Octave, NominalLabelsOfTheExactCentres) {
  // Thesis Table 3.4: the bands 63 Hz .. 1.25 kHz by their IEC 61260 nominal labels.
  const std::vector<double> table = {63, 80, 100, 125, 160, 200, 250, 315, 400, 500, 630, 800, 1000, 1250};
  const auto c = third_octave_centres(60.0, 1300.0);
  ASSERT_EQ(c.size(), table.size());
  for (std::size_t i = 0; i < c.size(); ++i) EXPECT_DOUBLE_EQ(third_octave_nominal(c[i]), table[i]) << c[i];
  // Below 1 Hz and across decades; a label maps to itself.
  EXPECT_DOUBLE_EQ(third_octave_nominal(1000.0 * std::pow(10.0, -3.3)), 0.5);
  EXPECT_DOUBLE_EQ(third_octave_nominal(0.1), 0.1);
  EXPECT_DOUBLE_EQ(third_octave_nominal(19952.6), 20000.0);
  EXPECT_DOUBLE_EQ(third_octave_nominal(31.5), 31.5);
  EXPECT_THROW(third_octave_nominal(0.0), InvalidParams);
}

TEST(Octave, BandAverageOfAKnownResponse) {
  std::vector<double> f;
  std::vector<std::complex<double>> h;
  for (double fr = 1.0; fr < 5000.0; fr += 1.0) {
    f.push_back(fr);
    h.push_back(fr < 500.0 ? std::complex<double>(0.0, 2.0) : std::complex<double>(0.1, 0.0));
  }
  const auto b = third_octave_average(f, h, 100.0, 2000.0);
  ASSERT_EQ(b.fc_Hz.size(), 14u);
  EXPECT_NEAR(b.mag_dB[0], 20 * std::log10(2.0), 1e-12);      // 100 Hz band: |H| = 2
  EXPECT_NEAR(b.mag_dB.back(), 20 * std::log10(0.1), 1e-12);  // 2 kHz band: |H| = 0.1
  // The 100 Hz band spans 89.1..112.2 Hz: 23 points at 1 Hz spacing.
  EXPECT_EQ(b.points[0], 23u);
}

}  // namespace
}  // namespace mc::dsp
