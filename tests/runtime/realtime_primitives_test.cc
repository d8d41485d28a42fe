#include <gtest/gtest.h>
#include <thread>

#include "microcobot/runtime/spsc_ring.h"
#include "microcobot/runtime/timing_stats.h"
#include "microcobot/runtime/watchdog.h"
#include "support/counting_allocator.h"

namespace mc::runtime {
namespace {

TEST(SpscRing, FifoOrderAndDropsWhenFull) {
  SpscRing<int> ring(3);
  EXPECT_TRUE(ring.push(1));
  EXPECT_TRUE(ring.push(2));
  EXPECT_TRUE(ring.push(3));
  EXPECT_FALSE(ring.push(4));
  EXPECT_EQ(ring.dropped(), 1u);
  int v = 0;
  EXPECT_TRUE(ring.pop(v));
  EXPECT_EQ(v, 1);
  EXPECT_TRUE(ring.push(5));
  for (int expected : {2, 3, 5}) {
    ASSERT_TRUE(ring.pop(v));
    EXPECT_EQ(v, expected);
  }
  EXPECT_FALSE(ring.pop(v));
}

TEST(SpscRing, TwoThreadsSeeEveryValueInOrderWithoutAllocating) {
  SpscRing<long> ring(1024);
  constexpr long kN = 200000;
  long received = 0, expected = 0;
  bool in_order = true;
  std::size_t allocations = 1;
  std::thread consumer([&] {
    long v = 0;
    while (received < kN) {
      if (ring.pop(v)) {
        in_order = in_order && v == expected;
        ++expected;
        ++received;
      }
    }
  });
  {
    test::AllocationGuard guard;
    for (long i = 0; i < kN;) {
      if (ring.push(i)) ++i;
    }
    allocations = guard.allocations();
  }
  consumer.join();
  EXPECT_TRUE(in_order);
  EXPECT_EQ(received, kN);
  EXPECT_EQ(allocations, 0u);
}

TEST(TimingStats, QuantilesMeanAndMax) {
  TimingStats s;
  for (int i = 1; i <= 100; ++i) s.add(i * 1e-6);  // 1..100 us
  EXPECT_EQ(s.count(), 100u);
  EXPECT_NEAR(s.mean_s(), 50.5e-6, 1e-12);
  EXPECT_DOUBLE_EQ(s.max_s(), 100e-6);
  EXPECT_NEAR(s.quantile_s(0.5), 50e-6, 0.11e-6);
  EXPECT_NEAR(s.quantile_s(0.99), 99e-6, 0.11e-6);
  s.add(5e-3);  // beyond the histogram: reported through max
  EXPECT_DOUBLE_EQ(s.quantile_s(1.0), 5e-3);
}

TEST(Watchdog, StaleAfterTheTimeoutFreshAgainWhenFed) {
  Watchdog w(3);
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(w.tick());
  EXPECT_FALSE(w.tick());
  for (int i = 0; i < 1000; ++i) EXPECT_FALSE(w.tick());
  w.feed();
  EXPECT_TRUE(w.fresh());
  EXPECT_TRUE(w.tick());
}

}  // namespace
}  // namespace mc::runtime
