// The coupling over a delayed, lossy link: the link emulator's contract, the
// passivity controllers' energy bounds, and the delay sweep's physics: the unprotected loop goes
// unstable in stiff contact as the delay grows, the protected one stays passive.
#include "microcobot/teleop/delayed_teleoperation.h"

#include <gtest/gtest.h>

#include <cmath>

#include "microcobot/core/error.h"
#include "microcobot/teleop/link_emulator.h"
#include "microcobot/teleop/passivity.h"
#include "support/counting_allocator.h"

namespace mc::teleop {
// The file's own namespace: its helpers keep their names beside the other test files of the
// module in a unity build (MC_UNITY_TESTS).
namespace passivity_test {
namespace {

TEST(EmulatedLink, DelaysHoldsTheLatestAndLosesItsShare) {
  EmulatedLink link({0.05, 0.0, 0.0, 3}, 1e-3);
  LinkSample got;
  for (int k = 0; k <= 100; ++k) {  // one sample per millisecond, each received at its time
    const double t = k * 1e-3;
    link.send({t, static_cast<double>(k), 0.0});
    const bool arrived = link.receive(t + 0.5e-3, got);
    EXPECT_EQ(arrived, k >= 50) << "nothing before 50 ms";
    if (arrived) {
      EXPECT_EQ(got.value, k - 50.0) << "the sample sent 50 ms earlier";
    }
  }
  ASSERT_TRUE(link.receive(10.0, got));
  EXPECT_EQ(got.value, 100.0) << "held after the last one";

  // Jitter and 20 % loss: what arrives is never older than what arrived before, and never
  // earlier than delay - jitter after it was sent.
  EmulatedLink lossy({0.1, 0.03, 0.2, 7}, 1e-3);
  double newest = -1.0;
  for (int k = 0; k < 20000; ++k) {
    const double t = k * 1e-3;
    lossy.send({t, t, 0.0});
    if (lossy.receive(t, got)) {
      EXPECT_GE(got.sent_s, newest);
      EXPECT_LE(got.sent_s, t - 0.07 + 1e-12);
      newest = got.sent_s;
    }
  }
  const double lost = static_cast<double>(lossy.lost()) / static_cast<double>(lossy.sent());
  EXPECT_NEAR(lost, 0.2, 3.0 * std::sqrt(0.2 * 0.8 / 20000.0)) << "binomial, 3 sigma";
  EXPECT_THROW(EmulatedLink({0.01, 0.02, 0.0, 1}, 1e-3), InvalidParams) << "jitter beyond the delay";
  EXPECT_THROW(EmulatedLink({0.01, 0.0, 1.0, 1}, 1e-3), InvalidParams) << "a link that loses everything";
}

TEST(PassivityControllers, EachPortOutputsOnlyTheEnergyThatHasArrived) {
  MasterPassivityController master(true);
  // The operator moves back (v < 0) against a force of 1 N: the channel would output 1 mJ in
  // 1 ms, but only 0.4 mJ has come in at the slave: the damper takes the rest.
  const double f = master.force(1.0, -1.0, 0.4e-3, 1e-3);
  EXPECT_NEAR(f * -1.0 * 1e-3, -0.4e-3, 1e-15);
  EXPECT_NEAR(master.observed_J(), 0.0, 1e-15);
  EXPECT_NEAR(master.dissipated_J(), 0.6e-3, 1e-15);
  // Input power is never limited, and counts as input.
  EXPECT_EQ(master.force(2.0, 1.0, 0.4e-3, 1e-3), 2.0);
  EXPECT_NEAR(master.energy().in_J, 2e-3, 1e-15);

  SlavePassivityController slave(true);
  // Pressing into the contact (f > 0, v > 0) with 0.5 mJ arrived from the master: the
  // commanded velocity is cut to what delivers that much.
  const double v = slave.velocity(2.0, 1.0, 0.5e-3, 1e-3);
  EXPECT_NEAR(v, 0.5, 1e-12);
  EXPECT_NEAR(slave.observed_J(), 0.0, 1e-15);
  SlavePassivityController observer(false);
  EXPECT_EQ(observer.velocity(2.0, 1.0, 0.5e-3, 1e-3), 2.0) << "observing only";
  EXPECT_NEAR(observer.observed_J(), -1.5e-3, 1e-15) << "the channel generated 1.5 mJ";
}

TEST(PassivityControllers, TheLinkAndTheControllersNeverAllocate) {
  EmulatedLink link({0.1, 0.01, 0.2, 1}, 1e-3);
  MasterPassivityController master(true);
  SlavePassivityController slave(true);
  LinkSample got;
  mc::test::AllocationGuard guard;
  double acc = 0.0;
  for (int k = 0; k < 5000; ++k) {
    link.send({k * 1e-3, std::sin(k * 1e-2), 1e-3 * k});
    if (link.receive(k * 1e-3, got)) acc += master.force(got.value, -0.1, got.energy_J, 1e-3);
    acc += slave.velocity(0.1, got.value, got.energy_J, 1e-3);
  }
  EXPECT_EQ(guard.allocations(), 0u);
  EXPECT_TRUE(std::isfinite(acc));
}

DelayCaseResult run(double delay, double loss, bool passivity) {
  return run_delay_case(DelayedTeleopParams{},
                        {delay, 0.05 * delay, loss, passivity ? Scheme::kTdpa : Scheme::kNone, 1});
}

TEST(DelayedTeleoperation, TheUnprotectedContactGoesUnstableAsTheDelayGrows) {
  for (double d : {0.0, 0.01}) {
    const auto r = run(d, 0.0, false);
    EXPECT_TRUE(r.stable) << d << " s: handle p-p " << r.max_handle_excursion_m;
    EXPECT_GT(r.max_contact_force_N, 1.5) << "it did push into the wall (the hand's 2 N)";
  }
  const auto r = run(0.1, 0.0, false);
  EXPECT_FALSE(r.stable);
  EXPECT_GT(r.max_handle_excursion_m, 5e-3) << "a sustained oscillation of the handle";
  EXPECT_LT(r.min_observed_energy_J, -0.1) << "the channel generated energy: not passive";
}

TEST(DelayedTeleoperation, PassivityControlKeepsTheChannelPassiveAtEveryDelayJitterAndLoss) {
  for (double d : {0.0, 0.05, 0.1, 0.2}) {
    for (double loss : {0.0, 0.2}) {
      const auto on = run(d, loss, true), off = run(d, loss, false);
      EXPECT_GE(on.min_observed_energy_J, -1e-12) << d << " s, loss " << loss;
      EXPECT_LE(on.max_handle_excursion_m, std::max(1e-4, 0.3 * off.max_handle_excursion_m))
          << d << " s, loss " << loss << ": the handle's motion is a fraction of the unprotected one's";
      if (d <= 0.1) {
        EXPECT_TRUE(on.stable) << d << " s, loss " << loss;
      }
      EXPECT_GT(on.max_contact_force_N, 1.0) << "the operator still feels and pushes the contact";
    }
  }
}

}  // namespace
}  // namespace passivity_test
}  // namespace mc::teleop
