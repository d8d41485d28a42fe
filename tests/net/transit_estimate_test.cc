// How late each sample of a stream arrives (transit_estimate.h): judged against the fastest the
// route has carried one, whatever the offset between the two ends' clocks, so that a backlog
// delivered after an outage is as old as it is.
#include "microcobot/net/transit_estimate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "microcobot/core/error.h"

namespace mc::net {
namespace {

constexpr double kPeriod = 1e-3;  // a 1 kHz state topic

// A route with a 0.3 ms delay, up to 0.4 ms of jitter, and the sender's clock `offset_s` ahead.
struct Route {
  double offset_s;
  std::mt19937 rng{28};
  std::uniform_real_distribution<double> jitter{0.0, 0.4e-3};
  double transit(double sent_at) { return (sent_at + 0.3e-3 + jitter(rng)) - (sent_at + offset_s); }
};

TEST(TransitEstimate, ASteadyStreamIsNeverLateWhateverTheClocksOffset) {
  for (const double offset : {0.0, 3.0, -1.7e9}) {
    TransitEstimate e(1.0);
    Route r{offset};
    double worst = 0.0;
    for (int k = 0; k < 5000; ++k) worst = std::max(worst, e.observe(r.transit(k * kPeriod), k * kPeriod));
    EXPECT_LE(worst, 0.4e-3 + 1e-9) << "offset " << offset << ": late by no more than the jitter";
    EXPECT_NEAR(e.estimate_s(), 0.3e-3 - offset, 1e-5) << "the fastest delivery, clock offset included";
  }
}

TEST(TransitEstimate, TheBacklogAfterAnOutageIsAsOldAsItIs) {
  // Poses flow, the cable is pulled for `outage` (longer than two windows in the second case),
  // then the 150 ms of poses queued before it arrive at once, then fresh ones.
  for (const double outage : {0.3, 5.0}) {
    TransitEstimate e(1.0);
    Route r{2.0};
    double t = 0.0;
    for (; t < 2.0; t += kPeriod) e.observe(r.transit(t), t);
    const double back = t + outage;
    for (int k = 150; k > 0; --k) {
      const double sent = back - k * kPeriod;
      const double late = e.observe(back - (sent + r.offset_s), back);
      EXPECT_NEAR(late, k * kPeriod - 0.3e-3, 0.5e-3) << "a pose measured " << k << " ms before it arrived";
    }
    // The route itself is unchanged: fresh poses are not late.
    for (double u = back; u < back + 3.0; u += kPeriod) EXPECT_LE(e.observe(r.transit(u), u), 0.4e-3 + 1e-9);
  }
}

TEST(TransitEstimate, ARouteThatBecameSlowerIsLearnedWithinTwoWindows) {
  TransitEstimate e(0.5);
  Route r{0.0};
  double t = 0.0;
  for (; t < 1.0; t += kPeriod) e.observe(r.transit(t), t);
  // 20 ms more from now on (a new route, or the sender's clock stepped back by 20 ms).
  const double changed = t;
  double last_late = t;
  for (; t < changed + 3.0; t += kPeriod)
    if (e.observe(r.transit(t) + 0.020, t) > 0.008) last_late = t;
  EXPECT_GT(last_late, changed + 0.4) << "late while the old route is in the window (the safe side)";
  EXPECT_LE(last_late, changed + 2 * 0.5 + kPeriod) << "learned within two windows";
  EXPECT_NEAR(e.estimate_s(), 0.3e-3 + 0.020, 1e-5);
}

TEST(TransitEstimate, ResetForgetsTheRouteAndBadInputIsNeverOnTime) {
  TransitEstimate e(1.0);
  EXPECT_TRUE(std::isinf(e.estimate_s()));
  EXPECT_EQ(e.observe(0.5, 0.0), 0.0) << "the first sample of a stream cannot be judged";
  EXPECT_NEAR(e.observe(0.6, 0.001), 0.1, 1e-12);
  EXPECT_TRUE(std::isinf(e.observe(std::numeric_limits<double>::quiet_NaN(), 0.002)));
  EXPECT_TRUE(std::isinf(e.observe(0.5, std::numeric_limits<double>::infinity())));
  e.reset();
  EXPECT_TRUE(std::isinf(e.estimate_s()));
  EXPECT_EQ(e.observe(0.6, 0.003), 0.0);
  EXPECT_THROW(TransitEstimate(0.0), Error);
  EXPECT_THROW(TransitEstimate{std::numeric_limits<double>::quiet_NaN()}, Error);
}

}  // namespace
}  // namespace mc::net
