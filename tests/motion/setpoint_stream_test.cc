// Setpoint streaming: 1 kHz setpoints, bounded look-ahead, late/missing ones hold.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/motion/setpoint_stream.h"
#include "support/counting_allocator.h"

namespace mc::motion {
namespace {

constexpr double kTick = 1e-4;  // the controller's 10 kHz

TEST(SetpointStream, InterpolatesBehindTheNewestSetpointByTheDelay) {
  SetpointStreamParams p;  // 2 ms look-ahead
  SetpointStream s(p, 0.0);
  // A ramp of 100 um/s sent at 1 kHz: x = 1e-4 t.
  double out = 0.0;
  for (int k = 0; k <= 1000; ++k) {
    const double t = k * kTick;
    if (k % 10 == 0) s.push(t, 1e-4 * t);
    out = s.sample(t, kTick).x_m;
  }
  // At t = 0.1 s the output is the ramp at t - 2 ms (interpolated), within the limiter's lag.
  EXPECT_NEAR(out, 1e-4 * (0.1 - p.delay_s), 1e-12);
  EXPECT_FALSE(s.holding());
}

TEST(SetpointStream, MissingSetpointsHoldAndLateOnesAreJoinedWithoutAJump) {
  SetpointStreamParams p;
  p.max_velocity_m_s = 200e-6;
  SetpointStream s(p, 0.0);
  double last = 0.0, max_step = 0.0;
  bool held = false;
  for (int k = 0; k <= 3000; ++k) {
    const double t = k * kTick;
    // Setpoints of a 100 um/s ramp, none between 50 and 150 ms (a dropout), then resumed.
    if (k % 10 == 0 && (t < 0.05 || t >= 0.15)) s.push(t, 1e-4 * t);
    const double x = s.sample(t, kTick).x_m;
    if (k > 0) max_step = std::max(max_step, std::abs(x - last));
    last = x;
    if (t > 0.06 && t < 0.15) {
      EXPECT_TRUE(s.holding());
      EXPECT_NEAR(x, 1e-4 * 0.049, 1e-9) << t;  // holds the newest setpoint, no extrapolation
      held = true;
    }
  }
  EXPECT_TRUE(held);
  // The 10 um gap after the dropout is closed under the velocity limit: never a jump.
  EXPECT_LE(max_step, 200e-6 * kTick * (1.0 + 1e-9));
  EXPECT_NEAR(last, 1e-4 * (0.3 - p.delay_s), 1e-12);  // caught up again
}

TEST(SetpointStream, RejectsOutOfOrderAndNonFiniteSetpointsAndStaysBounded) {
  SetpointStreamParams p;
  p.capacity = 4;
  SetpointStream s(p, 0.0);
  EXPECT_TRUE(s.push(1.0, 1e-6));
  EXPECT_FALSE(s.push(0.5, 2e-6));
  EXPECT_FALSE(s.push(1.0, 2e-6));
  EXPECT_FALSE(s.push(2.0, std::numeric_limits<double>::quiet_NaN()));
  EXPECT_FALSE(s.push(std::numeric_limits<double>::infinity(), 1e-6));
  for (int i = 0; i < 10; ++i) s.push(2.0 + i, 1e-6);
  EXPECT_EQ(s.size(), 4u);
  p.capacity = 1;
  EXPECT_THROW(p.validate(), InvalidParams);
}

TEST(SetpointStream, PushAndSampleNeverAllocate) {
  SetpointStream s(SetpointStreamParams{}, 0.0);
  mc::test::AllocationGuard guard;
  for (int k = 0; k < 5000; ++k) {
    if (k % 10 == 0) s.push(k * kTick, 1e-9 * k);
    s.sample(k * kTick, kTick);
  }
  EXPECT_EQ(guard.allocations(), 0u);
}

}  // namespace
}  // namespace mc::motion
