// Iterative learning control's law (motion/iterative_learning.h) on a repeatable plant: the
// convergence the survey's condition promises, the reset on a new identity, the tick path's
// allocations.
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/motion/iterative_learning.h"
#include "support/counting_allocator.h"

namespace mc::motion {
namespace {

/// A closed loop that puts the position on its plan two ticks late (as the tracking controller does
/// while the slider sticks) plus a repeatable error d(i): a lag and a bump of 200 nm.
struct DelayPlant {
  static constexpr int kDelay = 2;
  double disturbance(long i) const {
    const double t = static_cast<double>(i) * 1e-4;
    return 150e-9 * std::sin(2.0 * std::numbers::pi * 5.0 * t) +
           200e-9 * std::exp(-std::pow((t - 0.05) / 0.005, 2));
  }
  /// One trial of `n` ticks with `ilc`'s correction; returns the RMS error and learns.
  double trial(IterativeLearning& ilc, long n, std::uint64_t id = 7, double noise_m = 0.0,
               unsigned seed = 1) {
    ilc.begin_trial(id);
    std::vector<double> plan(static_cast<std::size_t>(n), 0.0);
    double sq = 0.0;
    unsigned s = seed;
    for (long i = 0; i < n; ++i) {
      plan[static_cast<std::size_t>(i)] = ilc.feedforward(i);  // the reference is 0: only the correction
      const double x = (i >= kDelay ? plan[static_cast<std::size_t>(i - kDelay)] : 0.0) + disturbance(i);
      s = s * 1103515245u + 12345u;
      const double n_m = noise_m * ((static_cast<double>((s >> 8) & 0xffff) / 65535.0) - 0.5) * 3.46;
      ilc.record(i, x + n_m);
      sq += x * x;
    }
    ilc.learn();
    return std::sqrt(sq / static_cast<double>(n));
  }
};

LearningParams exact_lead() {
  LearningParams p;
  p.learning_gain = 0.5;
  p.lead_ticks = DelayPlant::kDelay;  // L = gamma z^lambda inverts the delay
  p.q_cutoff_Hz = 500.0;
  return p;
}

TEST(IterativeLearning, TheErrorOfARepeatablePlantFallsMonotonically) {
  DelayPlant plant;
  const long n = 1000;
  IterativeLearning ilc(exact_lead(), n);
  double prev = plant.trial(ilc, n);
  const double first = prev;
  for (int k = 1; k < 12; ++k) {
    const double rms = plant.trial(ilc, n);
    EXPECT_LT(rms, prev) << "trial " << k;  // monotonic: |Q (1 - gamma z^lambda P)| < 1
    prev = rms;
  }
  EXPECT_LT(prev, 0.1 * first);
  EXPECT_EQ(ilc.trials(), 12);
}

TEST(IterativeLearning, NoiseDoesNotBuildUpWithForgettingAndQ) {
  // 50 nm of measurement noise, a new draw every trial: the correction stays bounded (Q and the
  // forgetting factor), the error settles, it does not creep back up.
  DelayPlant plant;
  const long n = 1000;
  LearningParams p = exact_lead();
  p.q_cutoff_Hz = 100.0;
  p.forgetting = 0.05;
  IterativeLearning ilc(p, n);
  const double first = plant.trial(ilc, n, 7, 50e-9, 1);
  std::vector<double> rms;
  for (int k = 1; k < 40; ++k) rms.push_back(plant.trial(ilc, n, 7, 50e-9, 1 + static_cast<unsigned>(k)));
  double middle = 0.0, last = 0.0;
  for (int k = 10; k < 20; ++k) middle += rms[static_cast<std::size_t>(k)] / 10.0;
  for (int k = 29; k < 39; ++k) last += rms[static_cast<std::size_t>(k)] / 10.0;
  for (int k = 5; k < 39; ++k) EXPECT_LT(rms[static_cast<std::size_t>(k)], 0.6 * first) << "trial " << k + 1;
  EXPECT_LT(last, 1.1 * middle);
}

TEST(IterativeLearning, ANewIdentityOrTheUsersResetForgetsTheCorrection) {
  DelayPlant plant;
  const long n = 500;
  IterativeLearning ilc(exact_lead(), n);
  plant.trial(ilc, n, 7);
  plant.trial(ilc, n, 7);
  EXPECT_EQ(ilc.trials(), 2);
  EXPECT_NE(ilc.feedforward(200), 0.0);
  ilc.begin_trial(8);  // another reference (or axis)
  EXPECT_EQ(ilc.trials(), 0);
  EXPECT_EQ(ilc.feedforward(200), 0.0);
  EXPECT_EQ(ilc.identity(), 8u);
  plant.trial(ilc, n, 8);
  EXPECT_NE(ilc.feedforward(200), 0.0);
  ilc.reset();
  EXPECT_EQ(ilc.feedforward(200), 0.0);
  EXPECT_FALSE(ilc.has_identity());
  // Identities: the same samples hash alike, a 1 pm change does not.
  ReferenceHash a, b, c;
  for (int i = 0; i < 100; ++i) {
    a.add(1e-6 * i);
    b.add(1e-6 * i);
    c.add(1e-6 * i + (i == 50 ? 1e-12 : 0.0));
  }
  EXPECT_EQ(a.value(), b.value());
  EXPECT_NE(a.value(), c.value());
}

TEST(IterativeLearning, TheTickPathAndTheLearningAllocateNothing) {
  DelayPlant plant;
  const long n = 2000;
  IterativeLearning ilc(exact_lead(), n);
  double acc = 0.0;
  mc::test::AllocationGuard guard;
  for (int k = 0; k < 3; ++k) {
    ilc.begin_trial(3);
    for (long i = 0; i < n + 10; ++i) {  // past the buffers: dropped, not grown
      acc += ilc.feedforward(i);
      ilc.record(i, plant.disturbance(i));
    }
    ilc.learn();
  }
  EXPECT_EQ(guard.allocations(), 0u);
  EXPECT_TRUE(std::isfinite(acc));
  EXPECT_EQ(ilc.dropped(), 10);
}

TEST(IterativeLearning, RejectsBadParameters) {
  LearningParams p;
  p.learning_gain = 2.0;
  EXPECT_THROW(IterativeLearning(p, 10), InvalidParams);
  p = {};
  p.q_cutoff_Hz = 6000.0;
  EXPECT_THROW(IterativeLearning(p, 10), InvalidParams);
  p = {};
  p.forgetting = 1.0;
  EXPECT_THROW(IterativeLearning(p, 10), InvalidParams);
  EXPECT_THROW(IterativeLearning(LearningParams{}, 0), InvalidParams);
}

}  // namespace
}  // namespace mc::motion
