// The arbiter of the live platform's inputs: who drives (rank, active over standby), what a
// hand-over does (every axis holds, the old holder released), who may release an e-stop, and
// that a tick allocates nothing.
#include "microcobot/live/command_arbiter.h"

#include <gtest/gtest.h>

#include <string>
#include <thread>

#include "microcobot/core/error.h"
#include "microcobot/platform/platform.h"
#include "support/counting_allocator.h"

namespace mc::live {
namespace {

class FakeSource final : public CommandSource {
 public:
  FakeSource(const char* name, double vx) : name_(name), vx_(vx) {}
  Claim claim = Claim::kNone;
  bool estop = false, reset_request = false;
  int drives = 0, releases = 0, publishes = 0, resets = 0;

  std::string_view name() const noexcept override { return name_; }
  SourceRequest poll(const SourceTick&) noexcept override { return {claim, estop, reset_request}; }
  void drive(const SourceTick&, teleop::ConsoleInput& in) noexcept override {
    ++drives;
    in.active = in.fresh = in.deadman = true;
    in.velocity_m_s = {vx_, 0.0, 0.0};
  }
  void released(const SourceTick&) noexcept override { ++releases; }
  void publish(const SourceTick&) noexcept override { ++publishes; }
  void reset() noexcept override { ++resets; }

 private:
  const char* name_;
  double vx_;
};

struct ArbiterRig {
  platform::PlatformConfig config;
  platform::Platform platform{config};
  runtime::TickInfo info{0, 0.0, 1e-3};
  FakeSource high{"high", 1.0}, middle{"middle", 2.0}, low{"low", 3.0};
  CommandArbiter arbiter;
  ArbiterRig() {
    arbiter.add(high);
    arbiter.add(middle);
    arbiter.add(low);
  }
  // One tick: the input the holder filled (inactive when nobody drove).
  teleop::ConsoleInput tick(CommandArbiter::Decision* d = nullptr) {
    teleop::ConsoleInput in;
    const SourceTick t{info, platform};
    const auto decision = arbiter.tick(t, in);
    arbiter.publish(t);
    if (d != nullptr) *d = decision;
    return in;
  }
};

TEST(CommandArbiter, TheHighestActiveDrivesElseTheHighestOnStandbyElseNobody) {
  ArbiterRig r;
  EXPECT_FALSE(r.tick().active) << "nobody asks: the input is left as it was";
  EXPECT_EQ(r.arbiter.holder(), -1);
  EXPECT_EQ(r.arbiter.holder_name(), "");

  r.low.claim = Claim::kStandby;
  r.middle.claim = Claim::kStandby;
  EXPECT_EQ(r.tick().velocity_m_s.x(), 2.0) << "the highest on standby";
  EXPECT_EQ(r.arbiter.holder_name(), "middle");

  r.low.claim = Claim::kActive;
  EXPECT_EQ(r.tick().velocity_m_s.x(), 3.0) << "an active source outranks any on standby";
  r.high.claim = Claim::kActive;
  EXPECT_EQ(r.tick().velocity_m_s.x(), 1.0) << "among the active, the first added";
  EXPECT_EQ(r.arbiter.holder_name(), "high");
  EXPECT_EQ(r.high.drives, 1);
  EXPECT_EQ(r.low.drives, 1) << "only the holder drives";
  EXPECT_EQ(r.middle.publishes, 4) << "every source publishes at every tick";
}

TEST(CommandArbiter, AHandOverHoldsEveryAxisAndReleasesTheOldHolderOnce) {
  ArbiterRig r;
  r.low.claim = Claim::kActive;
  r.tick();
  const auto handovers = r.arbiter.handovers();
  for (int i = 0; i < 5; ++i) r.tick();
  EXPECT_EQ(r.arbiter.handovers(), handovers) << "the same holder: no hand-over";
  EXPECT_EQ(r.low.releases, 0);

  r.high.claim = Claim::kActive;
  r.tick();
  EXPECT_EQ(r.arbiter.handovers(), handovers + 1);
  EXPECT_EQ(r.low.releases, 1);
  EXPECT_FALSE(r.platform.teleop().engaged) << "held: the coupling disengaged until it engages again";
  EXPECT_EQ(r.platform.teleop().slave_velocity_m_s.norm(), 0.0);

  r.high.claim = Claim::kNone;
  r.tick();
  EXPECT_EQ(r.high.releases, 1) << "a holder that stops asking is released too";
  EXPECT_EQ(r.arbiter.holder_name(), "low");

  r.arbiter.reset();
  EXPECT_EQ(r.arbiter.holder(), -1);
  EXPECT_EQ(r.low.resets, 1);
  EXPECT_EQ(r.high.resets, 1);
}

TEST(CommandArbiter, ASourcesEstopLatchesAtOnceAndOnlyItsOwnResetReleasesIt) {
  ArbiterRig r;
  r.middle.claim = Claim::kActive;
  r.middle.estop = true;
  r.tick();
  EXPECT_TRUE(r.platform.faulted()) << "latched within the tick";
  r.middle.estop = false;

  CommandArbiter::Decision d;
  r.low.reset_request = true;
  r.tick(&d);
  EXPECT_FALSE(d.reset) << "another source cannot release it";
  r.low.reset_request = false;
  r.middle.reset_request = true;
  r.tick(&d);
  EXPECT_TRUE(d.reset);
  r.tick(&d);
  EXPECT_FALSE(d.reset) << "asked once";
}

TEST(CommandArbiter, ATickAllocatesNothingAndTheSourcesAreBounded) {
  ArbiterRig r;
  r.low.claim = Claim::kStandby;
  {
    // This thread's allocations only: the rig's platform has threads of its own (its camera).
    test::AllocationGuard guard(std::this_thread::get_id());
    for (int i = 0; i < 1000; ++i) {
      r.high.claim = i % 100 < 50 ? Claim::kActive : Claim::kNone;  // hand-overs too
      r.tick();
    }
    EXPECT_EQ(guard.allocations(), 0u);
  }
  CommandArbiter full;
  FakeSource s("s", 0.0);
  for (std::size_t i = 0; i < CommandArbiter::kMaxSources; ++i) full.add(s);
  EXPECT_THROW(full.add(s), InvalidParams);
}

}  // namespace
}  // namespace mc::live
