// The two ends of the distributed platform in one process: a master live platform
// whose stage is the remote slave (net/remote_slave.h) and a slave live platform driven by the
// remote master (net/remote_master.h), over DDS on loopback, on this test's domain. Neither loop
// allocates while the link carries commands and measurements; the master's e-stop latches the
// slave's and its reset releases it.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "microcobot/live/live_platform.h"
#include "microcobot/net/remote_master.h"
#include "microcobot/net/remote_slave.h"
#include "microcobot/runtime/timing_stats.h"
#include "net/net_test_support.h"
#include "support/counting_allocator.h"
#include "support/test_support.h"

namespace mc::net {
namespace {

using namespace std::chrono_literals;

std::size_t channel(const char* name) { return platform::telemetry_channel_index(name); }

// A live platform keeping its latest telemetry sample (and every one while `recording`).
struct End {
  std::unique_ptr<live::LivePlatform> live;
  std::mutex mutex;
  platform::TelemetrySample last{};
  bool recording = false;
  std::vector<platform::TelemetrySample> recorded;
  explicit End(live::LiveParams p) : live(std::make_unique<live::LivePlatform>(std::move(p))) {
    live->start([this](const platform::TelemetrySample& s, std::size_t) {
      std::lock_guard lock(mutex);
      last = s;
      if (recording) recorded.push_back(s);  // the drain thread, off the loop
    });
  }
  void record(bool on) {
    std::lock_guard lock(mutex);
    recording = on;
  }
  double get(const char* name) {
    std::lock_guard lock(mutex);
    return last[channel(name)];
  }
  std::pair<double, double> get2(const char* a, const char* b) {
    std::lock_guard lock(mutex);
    return {last[channel(a)], last[channel(b)]};
  }
};

struct Pair {
  platform::PlatformConfig config;
  std::unique_ptr<RemoteSlave> slave_link;
  std::unique_ptr<RemoteMaster> master_link;
  std::unique_ptr<End> master, slave;

  explicit Pair(const teleop::LinkParams& emulate = {}, bool passivity = true, bool interpolate = true,
                const microworld::PickPlaceParams& world = {}, bool rotary = false) {
    config.world = world;
    const int domain = test::test_domain_id();
    RemoteMasterParams mp;
    mp.link.domain_id = domain;
    mp.emulate = emulate;
    mp.passivity = passivity;
    mp.interpolate_targets = interpolate;
    mp.rotary = rotary;
    mp.home_m = {config.stage.home_x_m, config.stage.home_y_m, config.stage.home_z_m};
    master_link = std::make_unique<RemoteMaster>(mp);
    live::LiveParams sp;
    sp.platform.world = config.world;
    sp.remote = master_link.get();
    slave = std::make_unique<End>(sp);

    const auto axis = platform::axis_params(config);
    RemoteSlaveParams rp;
    rp.link.domain_id = domain;
    rp.emulate = emulate;
    rp.passivity = passivity;
    rp.sample_period_s = axis.integrator.dt_s;
    if (rotary) rp.rotary = config.stage.rotary;
    slave_link = std::make_unique<RemoteSlave>(rp);
    live::LiveParams lp;
    lp.platform.world = config.world;
    lp.make_devices = [this] {
      devices::DeviceSet d = slave_link->make_devices();
      d.haptic = std::make_unique<devices::SimulatedHapticMaster>(
          "dual_stage", config.haptic.plant, config.haptic.render, config.haptic.pantograph,
          config.loop.period_s());
      d.tweezers = std::make_unique<devices::SimulatedTweezersMaster>("teletweez", config.tweezers,
                                                                      config.loop.period_s());
      return d;
    };
    master = std::make_unique<End>(lp);
    master->live->set_console_in_control(true);
  }
  ~Pair() {
    master.reset();  // before the links they use
    slave.reset();
  }
  // Sends `c` at 50 Hz to the master's console for `duration`.
  void drive(const live::ConsoleCommand& c, std::chrono::milliseconds duration) {
    const auto end = std::chrono::steady_clock::now() + duration;
    while (std::chrono::steady_clock::now() < end) {
      master->live->push_command(c);
      std::this_thread::sleep_for(20ms);
    }
  }
  // Holds the deadman until the master engages with the slave (30 s at most).
  bool engage();
};

live::ConsoleCommand jog(double vx) {
  live::ConsoleCommand c;
  c.deadman = true;
  c.velocity_m_s = {vx, 0, 0};
  return c;
}

bool Pair::engage() {
  return test::wait_until([&] { return master->get("engaged") == 1.0 || (drive(jog(0), 20ms), false); },
                          30.0);
}

// 100 ms each way, 10 ms of jitter, 20 % loss: a 200 ms round trip, the link the platform must stand.
// The platform's safety limits keep the fingers 10 um above the substrate, the grip
// under 1 mN and the stage still above a 2 mN contact: the passivity tests below need the stiff
// contact and the hard grip those limits forbid, so they lift them (a platform with a customer's
// parts never would).
microworld::PickPlaceParams without_safety_limits() {
  microworld::PickPlaceParams w;
  w.min_tip_height_m = -1e-3;
  w.grip_force_limit_N = 1.0;
  w.contact_force_limit_N = 10.0;
  return w;
}

teleop::LinkParams lossy_200ms_round_trip(std::uint64_t seed) {
  teleop::LinkParams link;
  link.delay_s = 0.1;
  link.jitter_s = 0.01;
  link.loss = 0.2;
  link.seed = seed;
  return link;
}

void moves_the_slave_without_allocating(Pair& pair);

TEST(RemoteEnds, TheMastersConsoleMovesTheSlaveAndNeitherLoopAllocates) {
  Pair pair;
  moves_the_slave_without_allocating(pair);
}

// The gripper's release burst over the link. The master's console holds Shake:
// the slave's gripper shakes only while the master is engaged (the deadman), and stops when the
// deadman is let go or the burst is.
TEST(RemoteEnds, TheMastersShakeReachesTheSlavesGripperOnlyWithTheDeadman) {
  Pair pair;
  ASSERT_TRUE(pair.engage());
  live::ConsoleCommand c = jog(0);
  c.has_gripper = true;
  c.gripper_opening_m = 400e-6;
  pair.drive(c, 300ms);
  EXPECT_EQ(pair.slave->get("gripper_shaking"), 0.0) << "nothing asked for the burst";
  c.gripper_shake = true;
  EXPECT_TRUE(test::wait_until(
      [&] { return pair.slave->get("gripper_shaking") == 1.0 || (pair.drive(c, 20ms), false); }, 10.0))
      << "the slave's gripper never shook";
  c.deadman = false;
  EXPECT_TRUE(test::wait_until(
      [&] { return pair.slave->get("gripper_shaking") == 0.0 || (pair.drive(c, 20ms), false); }, 10.0))
      << "the burst went on without the deadman";
  pair.drive(c, 300ms);
  EXPECT_EQ(pair.slave->get("gripper_shaking"), 0.0) << "Shake held without the deadman";
  c.deadman = true;
  c.gripper_shake = false;
  ASSERT_TRUE(pair.engage());
  pair.drive(c, 300ms);
  EXPECT_EQ(pair.slave->get("gripper_shaking"), 0.0) << "the burst let go";
}

// The rotary axis over the link. The master's console turns the slave's rotary
// axis (the target pose's orientation, a rotation about z) only while the master is engaged, and
// the master sees the slave's angle (the measured pose's orientation).
TEST(RemoteEnds, TheMastersConsoleTurnsTheSlavesRotaryAxisOverDds) {
  Pair pair({}, true, true, {}, /*rotary=*/true);
  ASSERT_TRUE(pair.engage());
  live::ConsoleCommand turn = jog(0);
  turn.has_theta_goal = true;
  turn.theta_goal_rad = 0.3;
  turn.deadman = false;
  pair.drive(turn, 1000ms);
  EXPECT_NEAR(pair.slave->get("slave_theta_rad"), 0.0, 1e-5) << "no deadman: nothing turns";
  turn.deadman = true;
  // 0.3 rad at 0.16 rad/s: 1.9 s of loop time (longer on a slow build, whose paced loop lags).
  test::wait_until(
      [&] {
        return std::abs(pair.slave->get("slave_theta_rad") - 0.3) < 1e-6 || (pair.drive(turn, 200ms), false);
      },
      30.0);
  pair.drive(turn, 200ms);
  const double slave_yaw = pair.slave->get("slave_theta_rad"), seen = pair.master->get("measured_theta_rad");
  std::printf("rotary over DDS: slave %.6f rad, seen by the master %.6f rad (goal 0.3)\n", slave_yaw, seen);
  EXPECT_NEAR(slave_yaw, 0.3, 1e-5);
  EXPECT_NEAR(seen, slave_yaw, 1e-5);
}

TEST(RemoteEnds, SoOverAnEmulatedLinkOf100msRoundTripWithJitterAndLoss) {
  teleop::LinkParams link;
  link.delay_s = 0.05;  // each way
  link.jitter_s = 0.005;
  link.loss = 0.2;
  Pair pair(link);
  moves_the_slave_without_allocating(pair);
}

void moves_the_slave_without_allocating(Pair& pair) {
  ASSERT_TRUE(pair.engage()) << "the master never engaged with the slave";
  const double x0 = pair.slave->get("measured_x_m");
  // One loop watched at a time (the counting allocator follows one thread), each while the
  // link carries targets one way and measurements the other.
  live::ConsoleCommand c = jog(200e-6);
  c.has_gripper = true;
  c.gripper_opening_m = 200e-6;
  for (const auto* end : {pair.master.get(), pair.slave.get()}) {
    std::size_t allocations = 0;
    {
      mc::test::AllocationGuard guard(end->live->loop_thread_id());
      pair.drive(c, 300ms);
      allocations = guard.allocations();
    }
    EXPECT_EQ(allocations, 0u) << (end == pair.master.get() ? "master" : "slave") << " loop";
  }
  ASSERT_TRUE(mc::test::eventually([&] {
    pair.drive(c, 20ms);
    return pair.slave->get("measured_x_m") > x0 + 50e-6 &&
           std::abs(pair.slave->get("gripper_opening_m") - 200e-6) < 10e-6;
  })) << "x moved "
      << 1e6 * (pair.slave->get("measured_x_m") - x0) << " um, gripper at "
      << 1e6 * pair.slave->get("gripper_opening_m") << " um";
  // The master sees what the slave measures.
  EXPECT_TRUE(mc::test::eventually([&] {
    pair.drive(jog(0), 20ms);
    return std::abs(pair.master->get("measured_x_m") - pair.slave->get("measured_x_m")) < 1e-6 &&
           std::abs(pair.master->get("gripper_opening_m") - pair.slave->get("gripper_opening_m")) < 1e-6;
  }));
  EXPECT_EQ(pair.master_link->link().stats().rejected_total(), 0u);
  EXPECT_EQ(pair.slave_link->link().stats().rejected_total(), 0u);
  // The link's work on the slave's loop thread (its remote end's poll and publish) is timed
  // there at every operator tick; the master's loop has no remote end (its stage is a device).
  runtime::TimingStats slave_cost(1e-8), master_cost(1e-8);
  pair.slave->live->drain_link_costs(slave_cost);
  pair.master->live->drain_link_costs(master_cost);
  EXPECT_GT(slave_cost.count(), 500u);  // one per ms over the drives above (the ring keeps 4096)
  EXPECT_GT(slave_cost.quantile_s(0.5), 0.0);
  EXPECT_LT(slave_cost.quantile_s(0.5), 0.5e-3) << "a fraction of the 1 ms operator period";
  EXPECT_EQ(master_cost.count(), 0u);
}

// Time-domain passivity across the two ends: over a 200 ms round trip with
// jitter and 20 % loss, the master's console presses the slave's fingers 5 um into the substrate
// (a 1e5 N/m contact). The slave reaches the contact 100 ms before the master hears of it, and
// the master's target has stopped before the force has come back: the master has put in far less
// energy than pressing 5 um deep takes out.
// (Not run under the sanitizers: the asan preset excludes it by name. The slave's port books
// the goal's motion against the contact force measured when the goal moves; a sanitized stage
// runs behind the wall clock and lagged its goal by over 5 um in one run, so that the goal had
// arrived before the contact began and the unprotected case observed nothing to contrast. The
// ports' bounds run under the sanitizers in passive_ports_test.cc.)
struct Press {
  double min_observed_master_end_J, min_observed_slave_end_J, dissipated_J, lowest_z_m, max_contact_N;
};

Press press_into_the_substrate(bool passivity) {
  Pair pair(lossy_200ms_round_trip(5), passivity, true, without_safety_limits());
  EXPECT_TRUE(pair.engage()) << "the master never engaged with the slave";
  live::ConsoleCommand c;
  c.deadman = true;
  c.has_goal = true;
  c.goal_m = {-1e-3, pair.master->get("target_y_m"), 20e-6};  // away from the part, 20 um up
  c.goal_speed_m_s = 1e-3;
  EXPECT_TRUE(mc::test::eventually([&] {
    pair.drive(c, 20ms);
    return std::abs(pair.slave->get("measured_z_m") - 20e-6) < 1e-6 &&
           std::abs(pair.slave->get("measured_x_m") + 1e-3) < 1e-6;
  })) << "z "
      << pair.slave->get("measured_z_m");
  EXPECT_EQ(pair.slave->get("contact_z_N"), 0.0) << "not yet in contact";
  c.goal_m[2] = -5e-6;
  c.goal_speed_m_s = 20e-6;
  Press p{};
  p.lowest_z_m = 1.0;
  // The master's target takes 1.25 s down to -5 um; on a loaded machine the coupling may let go
  // for a moment (a DDS deadline missed) and resume from where the slave is, which takes longer.
  // Pressed 4 um deep, or 10 s.
  const auto end = std::chrono::steady_clock::now() + 10000ms;
  while (std::chrono::steady_clock::now() < end && p.lowest_z_m > -4e-6) {
    pair.drive(c, 20ms);
    const auto [z, fz] = pair.slave->get2("measured_z_m", "contact_z_N");  // one sample
    p.lowest_z_m = std::min(p.lowest_z_m, z);
    p.max_contact_N = std::max(p.max_contact_N, fz);
  }
  std::printf("press (passivity %s): lowest z %.3f um, contact up to %.3f N\n", passivity ? "on" : "off",
              1e6 * p.lowest_z_m, p.max_contact_N);
  p.min_observed_master_end_J = pair.slave_link->min_observed_energy_J();
  p.min_observed_slave_end_J = pair.master_link->min_observed_energy_J();
  p.dissipated_J = pair.slave_link->dissipated_energy_J() + pair.master_link->dissipated_energy_J();
  return p;
}

TEST(RemoteEnds, PassivityControlKeepsTheChannelPassiveOver200msRoundTripWith20PercentLoss) {
  const Press open = press_into_the_substrate(false);
  EXPECT_GT(open.max_contact_N, 0.2) << "the unprotected slave pressed " << -1e6 * open.lowest_z_m
                                     << " um deep";
  EXPECT_LT(open.min_observed_slave_end_J, -1e-7)
      << "unprotected, the slave's end outputs energy the master has not put in";
  const Press protected_ = press_into_the_substrate(true);
  EXPECT_GE(protected_.min_observed_slave_end_J, -1e-15);
  EXPECT_GE(protected_.min_observed_master_end_J, -1e-15);
  EXPECT_GT(protected_.dissipated_J, 0.0) << "the slave's end held the goal back";
  RecordProperty("open_min_observed_J", std::to_string(open.min_observed_slave_end_J));
  RecordProperty("open_max_contact_N", std::to_string(open.max_contact_N));
  RecordProperty("protected_max_contact_N", std::to_string(protected_.max_contact_N));
  RecordProperty("protected_dissipated_J", std::to_string(protected_.dissipated_J));
  std::printf(
      "unprotected: min PO %.3g J, contact up to %.3g N; protected: min PO %.3g / %.3g J, contact up to "
      "%.3g N, dissipated %.3g J\n",
      open.min_observed_slave_end_J, open.max_contact_N, protected_.min_observed_slave_end_J,
      protected_.min_observed_master_end_J, protected_.max_contact_N, protected_.dissipated_J);
}

// The gripper's port: over the same 200 ms round trip with 20 % loss, the
// master's console closes the slave's fingers on the 300 um part, the opening target ramped from
// 400 to 150 um over 1 s. The slave's jaws squeeze while the master has not yet heard of the
// grip force: unprotected, the slave's end outputs energy the master has not put in (with the
// opening held at 400 um instead, both runs observe 0 J: the negative energy is the squeeze's).
// (Not run under the sanitizers, like the press above: the asan preset excludes it by name.)
struct Grasp {
  double min_observed_slave_end_J, min_observed_master_end_J, max_grip_N, master_grip_N;
};

Grasp grasp_across_the_link(bool passivity) {
  Pair pair(lossy_200ms_round_trip(9), passivity, true, without_safety_limits());
  EXPECT_TRUE(pair.engage()) << "the master never engaged with the slave";
  live::ConsoleCommand c;
  c.deadman = true;
  c.has_goal = true;
  c.goal_m = {0.0, 0.0, 100e-6};  // the fingers around the part (at the origin), 100 um up
  c.goal_speed_m_s = 1e-3;
  c.has_gripper = true;
  c.gripper_opening_m = 400e-6;
  EXPECT_TRUE(mc::test::eventually([&] {
    pair.drive(c, 20ms);
    return std::abs(pair.slave->get("measured_x_m")) < 1e-6 &&
           std::abs(pair.slave->get("measured_z_m") - 100e-6) < 1e-6 &&
           std::abs(pair.slave->get("gripper_opening_m") - 400e-6) < 5e-6;
  })) << "x "
      << pair.slave->get("measured_x_m") << ", z " << pair.slave->get("measured_z_m");
  EXPECT_EQ(pair.slave->get("grip_force_N"), 0.0) << "not yet gripping";
  Grasp g{};
  const auto start = std::chrono::steady_clock::now();
  for (;;) {
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (t > 2.0) break;
    c.gripper_opening_m = 400e-6 - 250e-6 * std::min(t, 1.0);
    pair.drive(c, 20ms);
    g.max_grip_N = std::max(g.max_grip_N, pair.slave->get("grip_force_N"));
  }
  g.master_grip_N = pair.master->get("grip_force_N");
  g.min_observed_master_end_J = pair.slave_link->min_observed_energy_J();
  g.min_observed_slave_end_J = pair.master_link->min_observed_energy_J();
  std::printf(
      "grasp (passivity %s): grip up to %.3g N at the slave, %.3g N at the master; min PO slave end %.3g J, "
      "master end %.3g J\n",
      passivity ? "on" : "off", g.max_grip_N, g.master_grip_N, g.min_observed_slave_end_J,
      g.min_observed_master_end_J);
  return g;
}

TEST(RemoteEnds, TheGrippersPortKeepsTheGraspPassiveOver200msRoundTripWith20PercentLoss) {
  const Grasp open = grasp_across_the_link(false);
  EXPECT_GT(open.max_grip_N, 1e-3) << "the unprotected fingers never gripped";
  EXPECT_LT(open.min_observed_slave_end_J, -1e-9)
      << "unprotected, the slave's end squeezes with energy the master has not put in";
  const Grasp protected_ = grasp_across_the_link(true);
  EXPECT_GE(protected_.min_observed_slave_end_J, -1e-15);
  EXPECT_GE(protected_.min_observed_master_end_J, -1e-15);
  EXPECT_GT(protected_.max_grip_N, 0.0) << "protected, the fingers still close on the part";
}

// The target stream at the slave's end: the master's console jogs at
// 200 um/s over a line of 50 ms, 5 ms of jitter and 20 % loss. The slave's target is fitted with
// a straight line over 1 s: followed as they arrive, the targets stop and jump; through the
// jitter buffer the slave retraces the master's motion. Returns the RMS off the line and the
// fitted speed, and the pace of the master's loop over that second (its loop time over the wall
// clock's: below 1 when a starved loop skipped ticks to catch up with the wall clock).
struct Roughness {
  double rms_m = 0.0, speed_m_s = 0.0, master_pace = 1.0;
};
Roughness slave_target_roughness(bool interpolate) {
  teleop::LinkParams link;
  link.delay_s = 0.05;
  link.jitter_s = 0.005;
  link.loss = 0.2;
  link.seed = 4;
  Pair pair(link, true, interpolate);
  EXPECT_TRUE(pair.engage()) << "the master never engaged with the slave";
  pair.drive(jog(200e-6), 500ms);  // up to speed
  pair.slave->record(true);
  const double master_t0 = pair.master->get("t_s");
  const auto wall0 = std::chrono::steady_clock::now();
  pair.drive(jog(200e-6), 1000ms);
  const double master_t1 = pair.master->get("t_s");
  const std::chrono::duration<double> wall = std::chrono::steady_clock::now() - wall0;
  pair.slave->record(false);
  std::vector<platform::TelemetrySample> r;
  {
    std::lock_guard lock(pair.slave->mutex);
    r = pair.slave->recorded;
  }
  const std::size_t t_ch = channel("t_s"), x_ch = channel("target_x_m");
  double n = static_cast<double>(r.size()), st = 0, sx = 0, stt = 0, stx = 0;
  for (const auto& s : r) st += s[t_ch], sx += s[x_ch], stt += s[t_ch] * s[t_ch], stx += s[t_ch] * s[x_ch];
  const double b = (n * stx - st * sx) / (n * stt - st * st), a = (sx - b * st) / n;
  double ss = 0;
  for (const auto& s : r) ss += std::pow(s[x_ch] - a - b * s[t_ch], 2);
  std::printf("slave target (%s): %zu samples, speed %.1f um/s, RMS off its line %.1f nm\n",
              interpolate ? "through the target stream" : "as targets arrive", r.size(), 1e6 * b,
              1e9 * std::sqrt(ss / n));
  EXPECT_GT(r.size(), 900u);
  return {std::sqrt(ss / n), b, (master_t1 - master_t0) / wall.count()};
}

// A run in which the slave did not keep the master's speed was disturbed from outside (seen once
// in 21 runs, inside ctest: the slave 27 um short after 1 s, as when a starved loop lets the
// coupling go for a moment; and in cold CI runs, 189.4 and 168 um/s with the targets 5 um off
// their line): it is run again, up to three times. An undisturbed run keeps the speed within 1 %.
// The master's jog advances with its loop's time: a master loop that skipped ticks meanwhile
// (its pace under 0.95 of the wall clock) sent the slave less motion, and its speed is not the
// slave's to keep.
double undisturbed_roughness_m(bool interpolate) {
  Roughness run;
  for (int attempt = 0; attempt < 3; ++attempt) {
    run = slave_target_roughness(interpolate);
    if (std::abs(run.speed_m_s - 200e-6) <= 4e-6) break;
  }
  if (run.master_pace >= 0.95)
    EXPECT_NEAR(run.speed_m_s, 200e-6, 20e-6) << "the slave follows the master's speed";
  else
    std::printf("the master's loop kept %.2f of the wall clock's pace: its speed not judged\n",
                run.master_pace);
  return run.rms_m;
}

TEST(RemoteEnds, TheSlaveRetracesTheMastersMotionThroughAJitteryLossyLine) {
  // The jitter buffer's playout is paced by the slave's loop: a loop kept off the CPU by other
  // work on the machine (a compiler beside the test: 670 nm at 198 um/s) plays the targets out
  // late. Such a run is repeated, up to three times; an undisturbed one retraces the line. The
  // targets as they arrive are measured again with each try: their roughness depends on how the
  // real threads met the emulated jitter (115-424 nm in five undisturbed runs), and a smooth
  // draw of it made the bound tighter than the buffered runs' own spread (2-36 nm).
  double raw = 0.0, buffered = 0.0;
  for (int attempt = 0; attempt < 3; ++attempt) {
    raw = undisturbed_roughness_m(false);
    buffered = undisturbed_roughness_m(true);
    if (buffered < 0.3 * raw) break;
  }
  EXPECT_LT(buffered, 0.3 * raw);
}

// A bare peer of `end`'s link (the other role, the same domain) that a test publishes through.
template <class EndParams>
LinkConfig peer_of(const EndParams& end, Role role) {
  LinkConfig c;
  c.domain_id = end.link.domain_id;
  c.role = role;
  return c;
}

// A sample from the peer's side of the link, once the two links have matched. It is sent until
// `received()` sees it; the copies still in flight then are given time to land and taken by one
// more `received()`, so that none arrives later, in the middle of a test's timed ticks.
template <class Received>
void deliver(Link& from, Channel channel, std::array<double, 3> xyz, double scalar, Received received) {
  NetSample s;
  s.channel = channel;
  s.stamp_ns = 1;
  s.xyz = xyz;
  s.scalar = scalar;
  ASSERT_TRUE(test::wait_until([&] { return from.peer_matched(); }, 20.0)) << "no peer";
  ASSERT_TRUE(test::wait_until([&] { return (from.send(s), received()); }, 20.0)) << "nothing arrived";
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  received();
}

TEST(RemoteEnds, AMasterLetsGoOfASlaveSilentFor8msInLoopTime) {
  RemoteSlaveParams rp;
  rp.link.domain_id = test::test_domain_id();
  rp.watch_dds = false;  // the peer sends one pose: the loop-time timeout alone is under test
  RemoteSlave remote(rp);
  Link peer(peer_of(rp, Role::kSlave));
  auto devices = remote.make_devices();
  EXPECT_FALSE(devices.axes[0]->measurement_fresh()) << "no pose yet";
  constexpr double kActive = static_cast<double>(devices::Lifecycle::kActive);
  deliver(peer, Channel::kSlaveDiagnostics, {kActive, kActive, kActive}, kActive, [&] {
    remote.exchange(0.0);
    return remote.state().slave_active();
  });
  deliver(peer, Channel::kMeasuredPose, {1e-6, 2e-6, 3e-6}, 0.0, [&] {
    remote.exchange(0.0);  // takes what arrived without ageing it
    return remote.fresh();
  });
  EXPECT_EQ(devices.axes[1]->position_m(), 2e-6);
  // 10 kHz ticks without a pose: fresh through 8 ms, silent from the next tick on.
  int fresh_ticks = 0;
  while (devices.axes[0]->measurement_fresh() && fresh_ticks < 1000) {
    remote.exchange(1e-4);
    ++fresh_ticks;
  }
  // The release comes at the tick that passes 8 ms (80 ticks of 0.1 ms, give or take the
  // rounding of their sum): 8.1 ms at the latest.
  EXPECT_GE(fresh_ticks, 80);
  EXPECT_LE(fresh_ticks, 81);
}

TEST(RemoteEnds, ASlaveHoldsWhenItsMastersTargetsAre8msOldInLoopTime) {
  platform::PlatformConfig config;
  RemoteMasterParams mp;
  mp.link.domain_id = test::test_domain_id();
  mp.home_m = {config.stage.home_x_m, config.stage.home_y_m, config.stage.home_z_m};
  mp.watch_dds = false;  // the peer sends single samples: the loop-time timeout alone is under test
  RemoteMaster remote(mp);
  Link peer(peer_of(mp, Role::kMaster));
  live::ConsoleCommand c;
  deliver(peer, Channel::kEngaged, {}, 1.0, [&] { return remote.poll(0.0, c), c.deadman; });
  deliver(peer, Channel::kTarget, {10e-6, 0, 0}, 0.0, [&] { return remote.poll(1.0, c).fresh; });
  // The master (re)appeared: the jitter buffer starts a new session, without the targets of the poll
  // that saw it. A master sends on (every ms): the target again until the goal moves. (With every
  // copy taken in that one poll, as a loaded machine may batch them, the goal had nothing to join.)
  double largest_step = 0.0, last = c.goal_m[0];
  deliver(peer, Channel::kTarget, {10e-6, 0, 0}, 0.0, [&] {
    remote.poll(1.0, c);
    largest_step = std::max(largest_step, std::abs(c.goal_m[0] - last));
    last = c.goal_m[0];
    return c.goal_m[0] > config.stage.home_x_m;
  });
  // A lone target is joined at the target stream's speed limit (1 mm/s: 1 um a poll), not by a jump.
  EXPECT_LE(largest_step, 1e-6 + 1e-12);
  for (int i = 0; i < 20; ++i) remote.poll(1.0, c);
  EXPECT_TRUE(c.has_goal);
  EXPECT_NEAR(c.goal_m[0], config.stage.home_x_m + 10e-6, 1e-12) << "targets are relative to home";
  // 1 kHz operator ticks after the target of t = 1 s: fresh through 8 ms, then the slave holds.
  EXPECT_TRUE(remote.poll(1.0079, c).fresh);
  EXPECT_FALSE(remote.poll(1.0081, c).fresh);
  // The master's e-stop latches, its release asks for the reset once.
  deliver(peer, Channel::kEstop, {}, 1.0, [&] { return remote.poll(1.01, c).estop; });
  live::RemoteRequest r;
  deliver(peer, Channel::kEstop, {}, 0.0, [&] { return (r = remote.poll(1.011, c)).reset; });
  EXPECT_FALSE(r.estop);
  EXPECT_FALSE(remote.poll(1.012, c).reset);
}

// Samples queued while the cable was out (in a socket, the kernel, a starved receive thread)
// arrive in a burst when it comes back, or even while it is still out. Each is as old as its
// stamp says, beyond the fastest delivery seen (transit_estimate.h): a burst of poses measured
// 40 to 11 ms ago does not take the slave back, nor does a burst of old targets the master.
std::int64_t sent_ns(double ago_s) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
             .count() -
         static_cast<std::int64_t>(ago_s * 1e9);
}

// Sends `count` samples on `channel`, calling `tick` after each, then waits 50 ms for them and
// ticks: `paced`, one per ms stamped as sent; else at once, stamped `ago_s`, `ago_s` - 1 ms, ...
// before now (a backlog).
template <class Tick>
void stream(Link& from, Channel channel, int count, double ago_s, bool paced, Tick tick) {
  for (int k = 0; k < count; ++k) {
    NetSample s;
    s.channel = channel;
    s.stamp_ns = sent_ns(paced ? 0.0 : ago_s - k * 1e-3);
    s.scalar = 0.0;
    from.send(s);
    if (paced) std::this_thread::sleep_for(1ms);
    tick();
  }
  std::this_thread::sleep_for(50ms);
  tick();
}

TEST(RemoteEnds, AMasterDoesNotTakeBackASlaveOnPosesQueuedWhileItWasCutOff) {
  RemoteSlaveParams rp;
  rp.link.domain_id = test::test_domain_id();
  rp.watch_dds = false;  // the peer sends poses only: the age of the poses is under test
  RemoteSlave remote(rp);
  Link peer(peer_of(rp, Role::kSlave));
  constexpr double kActive = static_cast<double>(devices::Lifecycle::kActive);
  deliver(peer, Channel::kSlaveDiagnostics, {kActive, kActive, kActive}, kActive, [&] {
    remote.exchange(0.0);
    return remote.state().slave_active();
  });
  // The route is learnt from a stream of poses sent as they are measured...
  bool fresh_on_time = false;
  stream(peer, Channel::kMeasuredPose, 200, 0.0, true, [&] {
    remote.exchange(0.0);
    fresh_on_time = fresh_on_time || remote.fresh();
  });
  ASSERT_TRUE(fresh_on_time) << "poses on time take the slave";
  // ...the cable is out: silent for 10 ms of loop time.
  for (int i = 0; i < 10; ++i) remote.exchange(1e-3);
  ASSERT_FALSE(remote.fresh());
  // The backlog: 30 poses measured 40 to 11 ms ago, at once.
  bool fresh_on_backlog = false;
  stream(peer, Channel::kMeasuredPose, 30, 0.040, false, [&] {
    remote.exchange(0.0);
    fresh_on_backlog = fresh_on_backlog || remote.fresh();
  });
  EXPECT_FALSE(fresh_on_backlog) << "poses 11 ms old or more are stale on arrival (timeout 8 ms)";
  // The cable is back: poses on time take it back.
  bool fresh_again = false;
  stream(peer, Channel::kMeasuredPose, 20, 0.0, true, [&] {
    remote.exchange(0.0);
    fresh_again = fresh_again || remote.fresh();
  });
  EXPECT_TRUE(fresh_again);
}

TEST(RemoteEnds, ASlaveDoesNotFollowTargetsQueuedWhileItsMasterWasCutOff) {
  RemoteMasterParams mp;
  mp.link.domain_id = test::test_domain_id();
  mp.watch_dds = false;  // the peer sends targets only: their age is under test
  RemoteMaster remote(mp);
  Link peer(peer_of(mp, Role::kMaster));
  live::ConsoleCommand c;
  double t = 0.0;  // the operator loop's time: a tick per sample sent
  deliver(peer, Channel::kEngaged, {}, 1.0, [&] { return remote.poll(t, c), c.deadman; });
  bool fresh_on_time = false;
  stream(peer, Channel::kTarget, 200, 0.0, true,
         [&] { fresh_on_time = remote.poll(t += 1e-3, c).fresh || fresh_on_time; });
  ASSERT_TRUE(fresh_on_time) << "targets on time take the slave";
  t += 0.010;  // 10 ms without a target: the slave holds
  ASSERT_FALSE(remote.poll(t, c).fresh);
  bool fresh_on_backlog = false;
  stream(peer, Channel::kTarget, 30, 0.040, false,
         [&] { fresh_on_backlog = remote.poll(t, c).fresh || fresh_on_backlog; });
  EXPECT_FALSE(fresh_on_backlog) << "targets 11 ms old or more are stale on arrival (timeout 8 ms)";
  bool fresh_again = false;
  stream(peer, Channel::kTarget, 20, 0.0, true,
         [&] { fresh_again = remote.poll(t += 1e-3, c).fresh || fresh_again; });
  EXPECT_TRUE(fresh_again);
}

// DDS's verdict feeds the watchdog: with no loop time passing at all, a slave
// that stops publishing is let go once its topics miss their deadline, and taken back when they
// flow again; a slave whose process is gone is let go too.
TEST(RemoteEnds, AMasterLetsGoOfASlaveWhoseTopicsMissTheirDdsDeadline) {
  RemoteSlaveParams rp;
  rp.link.domain_id = test::test_domain_id();
  RemoteSlave remote(rp);
  LinkConfig peer_config;
  peer_config.domain_id = rp.link.domain_id;
  peer_config.role = Role::kSlave;
  auto peer = std::make_unique<Link>(peer_config);
  auto publisher = std::make_unique<test::StatePublisher>(*peer);  // devices active, at 1 kHz
  const auto fresh = [&] {
    remote.exchange(0.0);  // drains what arrived; loop time stands still
    return remote.fresh();
  };
  ASSERT_TRUE(test::wait_until(fresh, 20.0)) << "matched " << remote.link().peer_matched();
  publisher->on = false;
  EXPECT_TRUE(test::wait_until([&] { return !fresh(); }, 5.0));
  EXPECT_GT(remote.link().stats().deadline_missed, 0u);
  publisher->on = true;
  EXPECT_TRUE(test::wait_until(fresh, 5.0));
  publisher.reset();
  peer.reset();
  EXPECT_TRUE(test::wait_until([&] { return !fresh(); }, 5.0));
}

TEST(RemoteEnds, TheMasterLetsGoOfASlaveThatStoppedItselfAndReEngagesAfterItsReset) {
  Pair pair;
  ASSERT_TRUE(pair.engage());
  pair.slave->live->estop();  // the slave's own console
  ASSERT_TRUE(mc::test::eventually([&] {
    pair.drive(jog(0), 20ms);
    return pair.master->get("engaged") == 0.0 && pair.master->get("stale") == 1.0;
  })) << "the master must let go of a slave in fault (its /diagnostics)";
  EXPECT_FALSE(pair.master->live->status().estopped) << "the master itself is fine";
  pair.slave->live->request(live::ConsoleAction::kReset);
  EXPECT_TRUE(mc::test::eventually([&] {
    pair.drive(jog(0), 20ms);
    return pair.master->get("engaged") == 1.0;
  })) << "the master re-engages once the slave is reset";
}

TEST(RemoteEnds, TheMastersEstopLatchesTheSlaveAndItsResetReleasesIt) {
  Pair pair;
  ASSERT_TRUE(pair.engage());
  pair.master->live->estop();
  ASSERT_TRUE(mc::test::eventually([&] { return pair.slave->live->status().estopped; }))
      << "the slave did not latch the master's e-stop";
  for (auto l : {pair.slave->live->status().lifecycle[0], pair.slave->live->status().lifecycle[3]})
    EXPECT_EQ(l, devices::Lifecycle::kFault);
  pair.master->live->request(live::ConsoleAction::kReset);
  ASSERT_TRUE(mc::test::eventually([&] {
    return !pair.master->live->status().estopped && !pair.slave->live->status().estopped;
  })) << "slave: "
      << pair.slave->live->status().last_error;
  const double x0 = pair.slave->get("measured_x_m");
  EXPECT_TRUE(mc::test::eventually([&] {
    pair.drive(jog(200e-6), 20ms);
    return pair.slave->get("measured_x_m") > x0 + 20e-6;
  })) << "the slave does not follow again after the reset";
}

}  // namespace
}  // namespace mc::net
