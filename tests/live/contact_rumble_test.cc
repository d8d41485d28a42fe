// The console's vibrotactile channel: the contact force's high band above the crossover, its RMS
// per frame, scaled to the full scale and clipped at 1.
#include "microcobot/live/contact_rumble.h"

#include <cmath>
#include <limits>
#include <numbers>

#include <gtest/gtest.h>

namespace mc::live {
namespace {

constexpr double kRate_Hz = 1000.0, kCrossover_Hz = 100.0, kFullScale_N = 5e-6;

// The rumble of one frame after a second of a sine of `amplitude_N` at `f_Hz` on x (the filter's
// transient gone), over the last `frame` samples.
double rumble_of(double f_Hz, double amplitude_N, int frame = 100) {
  ContactRumble r(kCrossover_Hz, kRate_Hz, kFullScale_N);
  for (int n = 0; n < 1000; ++n)
    r.add(amplitude_N * std::sin(2.0 * std::numbers::pi * f_Hz * n / kRate_Hz), 0, 0);
  r.take();
  for (int n = 1000; n < 1000 + frame; ++n)
    r.add(amplitude_N * std::sin(2.0 * std::numbers::pi * f_Hz * n / kRate_Hz), 0, 0);
  return r.take();
}

TEST(ContactRumble, TheHighBandPassesAtItsRmsAndTheLowBandDoesNot) {
  // 300 Hz, three times the crossover: the LR4 high-pass passes it within 2 % (|H| = 0.988);
  // a 2 uN sine is 1.41 uN RMS, 0.283 of the 5 uN full scale.
  EXPECT_NEAR(rumble_of(300.0, 2e-6), 2e-6 / std::sqrt(2.0) / kFullScale_N, 0.02 * 0.283);
  // 10 Hz, a decade below: -80 dB (|H| = 1e-4), nothing a hand feels.
  EXPECT_LT(rumble_of(10.0, 2e-6), 1e-3);
  // A static push is not a vibration at all.
  EXPECT_LT(rumble_of(0.0, 0.0), 1e-12);
}

TEST(ContactRumble, ClipsAtFullScaleAndReadsZeroWithoutSamples) {
  EXPECT_DOUBLE_EQ(rumble_of(300.0, 1e-3), 1.0);
  ContactRumble r(kCrossover_Hz, kRate_Hz, kFullScale_N);
  EXPECT_EQ(r.take(), 0.0);
}

TEST(ContactRumble, ASampleWithoutAForceDoesNotSilenceItForGood) {
  ContactRumble r(kCrossover_Hz, kRate_Hz, kFullScale_N);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  r.add(nan, nan, nan);
  EXPECT_EQ(r.take(), 0.0);
  for (int n = 0; n < 1000; ++n) r.add(0, 0, 2e-6 * std::sin(2.0 * std::numbers::pi * 300.0 * n / kRate_Hz));
  EXPECT_GT(r.take(), 0.2);
}

}  // namespace
}  // namespace mc::live
