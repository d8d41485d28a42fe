// runtime::LatestValue: the reader gets the newest value published, whole, while a writer
// publishes as fast as it can on another thread.

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <thread>

#include "microcobot/runtime/latest_value.h"

namespace mc::runtime {
namespace {

struct Wide {
  std::array<std::uint64_t, 16> v{};  ///< every entry the same: a torn copy would show
};

TEST(LatestValue, TheReaderGetsTheInitialValueThenTheNewest) {
  LatestValue<int> value(7);
  EXPECT_EQ(value.read(), 7);
  value.publish(1);
  value.publish(2);
  EXPECT_EQ(value.read(), 2);
  EXPECT_EQ(value.read(), 2);  // nothing newer: the same
  value.publish(3);
  EXPECT_EQ(value.read(), 3);
}

TEST(LatestValue, AValueReadWhileAnotherThreadPublishesIsNeverTornAndNeverGoesBack) {
  LatestValue<Wide> value;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    Wide w;
    for (std::uint64_t k = 1; k <= 200000; ++k) {
      w.v.fill(k);
      value.publish(w);
    }
    done = true;
  });
  std::uint64_t last = 0, reads = 0;
  while (!done.load() || reads < 10) {
    const Wide w = value.read();
    for (auto x : w.v) ASSERT_EQ(x, w.v[0]);
    ASSERT_GE(w.v[0], last);
    last = w.v[0];
    ++reads;
  }
  writer.join();
  EXPECT_EQ(value.read().v[0], 200000u);
}

}  // namespace
}  // namespace mc::runtime
