// The link emulator between two processes: delay, jitter and loss applied to
// what the DDS link delivers, per topic, losing only best-effort samples.
#include "microcobot/net/wire_emulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "microcobot/core/error.h"

namespace mc::net {
namespace {

NetSample pose(double x) {
  NetSample s;
  s.channel = Channel::kMeasuredPose;
  s.xyz = {x, 0, 0};
  return s;
}

NetSample estop(bool on) {
  NetSample s;
  s.channel = Channel::kEstop;
  s.scalar = on ? 1.0 : 0.0;
  return s;
}

TEST(WireEmulator, ASampleArrivesAfterTheDelayAndOnlyOnce) {
  teleop::LinkParams p;
  p.delay_s = 0.02;
  WireEmulator w(p, 1000.0);
  w.arrive(0.0, pose(1e-6));
  std::vector<double> got;
  for (int k = 0; k <= 40; ++k) w.deliver(1e-3 * k, [&](const NetSample& s) { got.push_back(s.xyz[0]); });
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0], 1e-6);
  // Delivered at 20 ms, not before.
  WireEmulator w2(p, 1000.0);
  w2.arrive(0.0, pose(1e-6));
  int calls = 0;
  w2.deliver(0.0199, [&](const NetSample&) { ++calls; });
  EXPECT_EQ(calls, 0);
  w2.deliver(0.0201, [&](const NetSample&) { ++calls; });
  EXPECT_EQ(calls, 1);
}

TEST(WireEmulator, BestEffortSamplesAreLostAtTheRateAndTheEstopNever) {
  teleop::LinkParams p;
  p.delay_s = 0.01;
  p.jitter_s = 0.005;
  p.loss = 0.2;
  WireEmulator w(p, 1000.0);
  int poses = 0, estops = 0;
  bool last_estop = false;
  for (int k = 0; k < 5000; ++k) {
    const double t = 1e-3 * k;
    w.arrive(t, pose(1e-9 * k));
    if (k % 10 == 0) w.arrive(t, estop(k % 20 == 0));
    w.deliver(t, [&](const NetSample& s) {
      if (s.channel == Channel::kMeasuredPose) ++poses;
      if (s.channel == Channel::kEstop) ++estops, last_estop = s.scalar != 0.0;
    });
  }
  w.deliver(10.0, [&](const NetSample& s) {
    if (s.channel == Channel::kEstop) ++estops, last_estop = s.scalar != 0.0;
  });
  // 20 % lost, and with +-5 ms of jitter at 1 kHz a keep-latest reader also skips the samples
  // overtaken by newer ones (measured: about a third delivered): fewer than 80 %, never none.
  EXPECT_LT(poses, 4000 + 100);
  EXPECT_GT(poses, 1000);
  EXPECT_NEAR(static_cast<double>(w.lost()) / 5000.0, 0.2, 0.03) << "only best-effort samples are lost";
  EXPECT_FALSE(last_estop) << "the last e-stop state sent (released) is the one that stays";
  EXPECT_GT(estops, 100);
}

TEST(WireEmulator, TheNewestOfABurstInOneTickWins) {
  WireEmulator w(teleop::LinkParams{.delay_s = 0.001}, 1000.0);
  w.arrive(0.0, estop(true));
  w.arrive(0.0, estop(false));
  std::vector<double> got;
  w.deliver(0.01, [&](const NetSample& s) { got.push_back(s.scalar); });
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0], 0.0);
}

TEST(WireEmulator, RefusesBadParameters) {
  EXPECT_THROW(WireEmulator(teleop::LinkParams{.delay_s = 0.01, .jitter_s = 0.02}, 1000.0), InvalidParams);
  EXPECT_THROW(WireEmulator(teleop::LinkParams{.loss = 1.0}, 1000.0), InvalidParams);
  EXPECT_THROW(WireEmulator(teleop::LinkParams{}, 0.0), InvalidParams);
}

}  // namespace
}  // namespace mc::net
