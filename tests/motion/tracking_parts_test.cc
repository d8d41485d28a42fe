// The tracking controller's parts: the damping's band-pass (0 dB at its centre, at rest from its
// first sample), the catch-up's raised cosine and the backslip estimate's landing and learning.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "microcobot/motion/backslip_estimate.h"
#include "microcobot/motion/catch_up.h"
#include "microcobot/motion/damping_band_pass.h"

namespace mc::motion {
namespace {

// The gain at `f_Hz` from the output's RMS over the second half second (whole periods of both
// frequencies tested), the transient gone.
double band_pass_gain(double f_Hz) {
  DampingBandPass bp(1640.0, 2.0, 20000.0);
  double sum = 0.0;
  for (int n = 0; n < 20000; ++n) {
    const double y = bp.step(std::sin(2.0 * std::numbers::pi * f_Hz * n / 20000.0));
    if (n >= 10000) sum += y * y;
  }
  return std::sqrt(2.0 * sum / 10000.0);
}

TEST(DampingBandPass, PassesItsCentreAt0dBAndAttenuatesADecadeAway) {
  EXPECT_NEAR(band_pass_gain(1640.0), 1.0, 0.01);
  EXPECT_LT(band_pass_gain(164.0), 0.06);  // Q 2: |H| = 1 / sqrt(1 + Q^2 (f/f0 - f0/f)^2) = 0.05
}

TEST(DampingBandPass, StartsAtRestOnItsFirstSample) {
  DampingBandPass bp(1640.0, 2.0, 20000.0);
  EXPECT_EQ(bp.step(5e-3), 0.0);  // a position far from zero is not a step
  EXPECT_EQ(bp.step(5e-3), 0.0);
  EXPECT_EQ(bp.previous(), 0.0);
  const double y = bp.step(5e-3 + 1e-9);
  EXPECT_GT(y, 0.0);
  bp.step(5e-3 + 1e-9);
  EXPECT_EQ(bp.previous(), y);
  bp.reset();
  EXPECT_EQ(bp.step(-1.0), 0.0);
}

TEST(CatchUp, MovesAlongARaisedCosineWithZeroSlopeAtBothEnds) {
  CatchUp c;
  c.restart(2e-6);
  EXPECT_EQ(c.update(0.0), 0.0);
  EXPECT_NEAR(c.update(0.5), 1e-6, 1e-18);
  EXPECT_EQ(c.update(1.0), 2e-6);
  EXPECT_EQ(c.update(3.0), 2e-6);
  EXPECT_NEAR(CatchUp::blend(1e-3), 0.0, 1e-5);  // zero slope: quadratic at the start
  EXPECT_NEAR(CatchUp::blend(1.0 - 1e-3), 1.0, 1e-5);
  // A miss on the way: from where it is to the new goal.
  c.restart(2e-6);
  c.update(0.5);
  c.add(-1e-6);
  EXPECT_NEAR(c.remaining(), 0.0, 1e-18);
  EXPECT_NEAR(c.update(0.0), 1e-6, 1e-18);
  c.reset();
  EXPECT_EQ(c.now(), 0.0);
  EXPECT_EQ(c.remaining(), 0.0);
}

TEST(BackslipEstimate, LandsBackFromTheEdgeAndLearnsFromItsMissPerDirection) {
  BackslipEstimate b;
  b.set(100e-9, 80e-9);
  b.edge_at(10e-6, true);
  EXPECT_NEAR(b.landing_m(), 10e-6 - 100e-9, 1e-18);  // forward: dragged back
  b.await_outcome();
  EXPECT_TRUE(b.awaiting_outcome());
  b.settle(20e-9, 0.5, true);  // landed 20 nm short of the plan: the backslip was larger
  EXPECT_FALSE(b.awaiting_outcome());
  EXPECT_NEAR(b.of(true), 110e-9, 1e-18);
  EXPECT_NEAR(b.of(false), 80e-9, 1e-18);
  b.edge_at(10e-6, false);
  EXPECT_NEAR(b.landing_m(), 10e-6 + 80e-9, 1e-18);
  b.settle(200e-9, 1.0, true);  // never below zero
  EXPECT_EQ(b.of(false), 0.0);
  b.edge_at(0.0, false, 0.0);  // the power-up's ramp-in: no backslip expected, nothing learnt
  EXPECT_EQ(b.landing_m(), 0.0);
  b.settle(-50e-9, 1.0, false);
  EXPECT_EQ(b.of(false), 0.0);
}

}  // namespace
}  // namespace mc::motion
