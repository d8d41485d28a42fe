// The simulated person's motor model: minimum-jerk sub-movements timed by
// Fitts' law, endpoint noise proportional to the amplitude, the reaction time, tremor in its band.
#include "microcobot/cell/person_model.h"

#include <cmath>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"

namespace mc::cell {
namespace person_model_test {
namespace {

PersonParams quiet() {
  PersonParams p;
  p.endpoint_sd_fraction = 0.0;
  return p;
}

TEST(PersonModel, AMovementIsAMinimumJerkProfile) {
  const PersonParams p = quiet();
  Rng rng(1);
  Reach r(p, rng);
  r.reset({0, 0}, 0.0);
  r.move({0.02, 0}, 0.5, 0.0);
  EXPECT_NEAR(r.position(0.25).x(), 0.01, 1e-12);                // half-way at half-time
  EXPECT_NEAR(r.velocity(0.25).x(), 1.875 * 0.02 / 0.5, 1e-12);  // its peak: 1.875 D / T
  EXPECT_NEAR(r.velocity(1e-9).x(), 0.0, 1e-9);                  // smooth start and end
  EXPECT_NEAR(r.position(0.5).x(), 0.02, 1e-15);
  EXPECT_FALSE(r.moving(0.5));
}

TEST(PersonModel, ASubMovementLastsWhatFittsLawSaysAndIsSeenAReactionLater) {
  const PersonParams p = quiet();
  Rng rng(2);
  Reach r(p, rng);
  r.reset({0, 0}, 0.0);
  const double d = 0.03, w = 0.001;
  EXPECT_FALSE(r.ready(0.1));  // the person first takes in the scene
  const double t0 = p.reaction_time_s;
  EXPECT_FALSE(r.aim({d, 0}, w, t0));  // starts
  const double mt = p.fitts_a_s + p.fitts_b_s_per_bit * std::log2(d / w + 1.0);
  EXPECT_TRUE(r.moving(t0 + mt - 1e-6));
  EXPECT_FALSE(r.moving(t0 + mt + 1e-9));
  // Arrived, but known only a reaction time after the end.
  EXPECT_FALSE(r.aim({0, 0}, w, t0 + mt + 0.5 * p.reaction_time_s));
  EXPECT_TRUE(r.aim({0, 0}, w, t0 + mt + p.reaction_time_s));
  EXPECT_EQ(r.submovements(), 1);
}

TEST(PersonModel, TheEndpointMissesInProportionToTheAmplitude) {
  PersonParams p;
  Rng rng(3);
  for (const double d : {1e-3, 20e-3}) {
    double sum = 0, sum2 = 0;
    const int n = 4000;
    for (int i = 0; i < n; ++i) {
      Reach r(p, rng);
      r.reset({0, 0}, 0.0);
      r.aim({d, 0}, 1e-9, 1.0);
      const double miss = r.end().x() - d;
      sum += miss;
      sum2 += miss * miss;
    }
    const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
    EXPECT_NEAR(sd / d, p.endpoint_sd_fraction, 0.1 * p.endpoint_sd_fraction) << d;
    EXPECT_LT(std::abs(mean), 4 * sd / std::sqrt(n)) << d;
  }
}

TEST(PersonModel, TremorHasItsRmsInItsBand) {
  const PersonParams p;
  Tremor tremor(p, 1000.0, 9);
  const int n = 120000;  // two minutes at 1 kHz
  double sum2 = 0;
  int crossings = 0;
  double last = 0;
  for (int i = 0; i < n; ++i) {
    const double x = tremor.next().x();
    if (i > 2000) {  // the band-pass settled
      sum2 += x * x;
      if ((x > 0) != (last > 0)) ++crossings;
    }
    last = x;
  }
  const double seconds = (n - 2001) / 1000.0;
  EXPECT_NEAR(std::sqrt(sum2 / (n - 2001)), p.tremor_rms_m, 0.1 * p.tremor_rms_m);
  // A narrow band's zero crossings come at twice its centre frequency.
  const double f = crossings / (2.0 * seconds);
  EXPECT_GT(f, p.tremor_low_Hz);
  EXPECT_LT(f, p.tremor_high_Hz);
}

TEST(PersonModel, BadParametersAreNamed) {
  PersonParams p;
  p.tremor_high_Hz = 5.0;  // below the low edge
  try {
    p.validate();
    FAIL();
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("tremor_high_Hz"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace person_model_test
}  // namespace mc::cell
