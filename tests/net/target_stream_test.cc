// The master's targets at the slave's end (over the network link): through
// the jitter buffer, a ramp sent at 1 kHz over a line with delay, jitter, loss and a clock offset
// comes out as the same ramp, delayed; followed as the targets arrive, it stops and jumps.
#include "microcobot/net/target_stream.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "microcobot/teleop/link_emulator.h"
#include "support/counting_allocator.h"

namespace mc::net {
// The file's own namespace: its helpers keep their names beside the other test files of the
// module in a unity build (MC_UNITY_TESTS).
namespace target_stream_test {
namespace {

constexpr double kDt = 1e-3;
constexpr double kSpeed = 200e-6;  // m/s along x

struct Followed {
  double rms_jerkiness_m = 0.0;  // RMS deviation of the followed x from its best straight line
  double max_step_m = 0.0;       // the largest change of x in one tick (after 1 s)
  double lag_s = 0.0;            // behind the sender, from the fit
  std::size_t allocations = 0;
};

// 3 s of a 200 um/s ramp, sent each ms stamped with a clock 3 s ahead of this end's, over
// `line`; the receiver follows the stream (or the latest target) each ms; fitted over 1-3 s.
Followed follow_ramp(const teleop::LinkParams& line, bool buffered) {
  motion::SetpointStreamParams sp;  // RemoteMaster's, with an emulated jitter: look-ahead 2 J + 1 ms
  sp.delay_s = std::max(2e-3, 2.0 * line.jitter_s + 1e-3);
  sp.capacity = 64;
  sp.max_velocity_m_s = 1e-3;
  TargetStream stream(sp);
  teleop::EmulatedLink wire(line, kDt);
  const double offset_s = 3.0;
  std::array<double, 3> latest{};
  std::vector<double> t, x;
  t.reserve(3000), x.reserve(3000);
  Followed r;
  double previous = 0.0, last_sent = -1.0;
  {
    mc::test::AllocationGuard guard;
    for (int k = 0; k < 3000; ++k) {
      const double now = k * kDt;
      wire.send({now, kSpeed * now, 0.0});  // sent at, position
      teleop::LinkSample got;  // the newest arrived (the link keeps the latest, as a DDS reader may)
      if (wire.receive(now, got) && got.sent_s > last_sent) {
        last_sent = got.sent_s;
        stream.push(got.sent_s + offset_s, {got.value, 0.0, 0.0}, now);
        latest = {got.value, 0.0, 0.0};
      }
      const double followed = buffered ? stream.sample(now, kDt)[0] : latest[0];
      if (now >= 1.0) {  // past the start (the first target is joined at the speed limit)
        r.max_step_m = std::max(r.max_step_m, std::abs(followed - previous));
        t.push_back(now), x.push_back(followed);
      }
      previous = followed;
    }
    r.allocations = guard.allocations();
  }
  // Least-squares line x = a + b t.
  const double n = static_cast<double>(t.size());
  double st = 0, sx = 0, stt = 0, stx = 0;
  for (std::size_t i = 0; i < t.size(); ++i) st += t[i], sx += x[i], stt += t[i] * t[i], stx += t[i] * x[i];
  const double b = (n * stx - st * sx) / (n * stt - st * st), a = (sx - b * st) / n;
  double ss = 0;
  for (std::size_t i = 0; i < t.size(); ++i) ss += (x[i] - a - b * t[i]) * (x[i] - a - b * t[i]);
  r.rms_jerkiness_m = std::sqrt(ss / n);
  r.lag_s = -a / b;
  return r;
}

TEST(TargetStream, AJitteryLossyLineDeliversTheMastersRampSmoothlyAndDelayedNotInJumps) {
  teleop::LinkParams line;
  line.delay_s = 0.05;
  line.jitter_s = 0.005;
  line.loss = 0.2;
  line.seed = 3;
  const Followed raw = follow_ramp(line, false), buffered = follow_ramp(line, true);
  std::printf(
      "latest target: RMS off its line %.1f nm, largest step %.0f nm; buffered: %.2f nm, %.0f nm, lag %.1f "
      "ms\n",
      1e9 * raw.rms_jerkiness_m, 1e9 * raw.max_step_m, 1e9 * buffered.rms_jerkiness_m,
      1e9 * buffered.max_step_m, 1e3 * buffered.lag_s);
  // Followed as they arrive: bursts and gaps of several ms, steps of a micrometre.
  EXPECT_GT(raw.max_step_m, 1e-6);
  // Through the buffer: the ramp itself (0.2 nm a tick at 200 um/s), a few nm off its line.
  EXPECT_LT(buffered.max_step_m, 0.5e-6);
  EXPECT_LT(buffered.rms_jerkiness_m, 0.1 * raw.rms_jerkiness_m);
  // Behind the sender by the fastest transit (45 ms) and the look-ahead (11 ms), not more.
  EXPECT_NEAR(buffered.lag_s, 0.045 + 0.011, 2e-3);
  EXPECT_EQ(buffered.allocations, 0u);
}

TEST(TargetStream, LateTargetsHoldAndAreRejoinedAtTheSpeedLimitNeverByAJump) {
  motion::SetpointStreamParams sp;
  sp.delay_s = 2e-3;
  sp.max_velocity_m_s = 1e-3;
  TargetStream stream(sp);
  // Targets at 0 for 100 ms, then nothing for 50 ms while the master moved 20 um away.
  double now = 0.0;
  for (int k = 0; k < 100; ++k, now += kDt) {
    stream.push(now, {0.0, 0.0, 0.0}, now + 0.5e-3);
    stream.sample(now + 0.5e-3, kDt);
  }
  for (int k = 0; k < 50; ++k, now += kDt) EXPECT_NEAR(stream.sample(now + 0.5e-3, kDt)[0], 0.0, 1e-12);
  EXPECT_TRUE(stream.holding());
  stream.push(now, {20e-6, 0.0, 0.0}, now + 0.5e-3);
  double x = 0.0;
  for (int k = 0; k < 30; ++k, now += kDt) {
    const double next = stream.sample(now + 0.5e-3, kDt)[0];
    EXPECT_LE(next - x, 1e-3 * kDt + 1e-15) << "a step beyond the speed limit at tick " << k;
    x = next;
  }
  EXPECT_NEAR(x, 20e-6, 1e-12) << "rejoined within 20 ms";
}

TEST(TargetStream, AStampFromTheFutureIsDroppedAndDoesNotFreezeTheGoal) {
  TargetStream stream(motion::SetpointStreamParams{});
  double now = 0.0;
  for (int k = 0; k < 50; ++k, now += kDt) {
    ASSERT_TRUE(stream.push(now, {k * 1e-9, 0.0, 0.0}, now + 1e-3));
    stream.sample(now + 1e-3, kDt);
  }
  // A corrupt stamp a year ahead (a finite, valid ROS time): refused, the stream goes on.
  EXPECT_FALSE(stream.push(now + 3.15e7, {1e-3, 0.0, 0.0}, now + 1e-3));
  EXPECT_FALSE(stream.push(std::nan(""), {0.0, 0.0, 0.0}, now));
  for (int k = 50; k < 100; ++k, now += kDt) {
    ASSERT_TRUE(stream.push(now, {k * 1e-9, 0.0, 0.0}, now + 1e-3)) << k;
    stream.sample(now + 1e-3, kDt);
  }
  EXPECT_NEAR(stream.sample(now + 1e-3, kDt)[0], 97e-9, 2e-9) << "still following the sender";
  EXPECT_NEAR(stream.transit_s(), 1e-3, 1e-9);
}

}  // namespace
}  // namespace target_stream_test
}  // namespace mc::net
