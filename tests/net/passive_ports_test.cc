// Time-domain passivity across the two processes: each end outputs only the
// energy the other has put in and that has arrived; a peer's restart opens a new session; the
// channel between the two ends never creates energy, whatever the delay, jitter, loss and the
// signals.
#include "microcobot/net/passive_ports.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <random>

#include "microcobot/teleop/link_emulator.h"

namespace mc::net {
namespace {

constexpr double kDt = 1e-3;

TEST(PassivePorts, NothingLeavesTheSlavesEndBeforeTheMastersEnergyArrivesThenExactlyThat) {
  SlavePorts slave(true);
  // The stage asked at 1 mm/s into a contact that pushes back with 1 N: 1 uJ per tick.
  const Axes3 asked{1e-3, 0, 0}, contact{-1.0, 0, 0};
  EXPECT_EQ(slave.velocity(asked, contact, kDt)[0], 0.0) << "no session yet: nothing may leave";
  slave.arrived({0.5e-6, 0, 0});  // opens the session: counts from here
  EXPECT_NEAR(slave.velocity(asked, contact, kDt)[0], 0.0, 1e-15);
  slave.arrived({2.0e-6, 0, 0});  // 1.5 uJ of the master's arrived
  EXPECT_NEAR(slave.velocity(asked, contact, kDt)[0], 1e-3, 1e-15) << "all of the first uJ";
  EXPECT_NEAR(slave.velocity(asked, contact, kDt)[0], 0.5e-3, 1e-15) << "the half that is left";
  EXPECT_NEAR(slave.velocity(asked, contact, kDt)[0], 0.0, 1e-15);
  const PortsReport r = slave.report();
  EXPECT_NEAR(r.output_energy_J[0], 1.5e-6, 1e-18);
  EXPECT_GE(r.min_observed_J, -1e-18);
  EXPECT_NEAR(r.dissipated_J, 1e-6 + 1e-6 + 0.5e-6 + 1e-6, 1e-18) << "what was refused, tick by tick";
  // Moving away from the contact takes energy in, freely.
  EXPECT_NEAR(slave.velocity({-1e-3, 0, 0}, contact, kDt)[0], -1e-3, 1e-15);
  EXPECT_NEAR(slave.report().input_energy_J[0], 1e-6, 1e-18);
  // Without the controller the same requests pass and the observer goes negative.
  SlavePorts open(false);
  EXPECT_EQ(open.velocity(asked, contact, kDt)[0], 1e-3);
  EXPECT_NEAR(open.report().min_observed_J, -1e-6, 1e-18);
}

TEST(PassivePorts, ARestartedPeerOpensANewSessionAndOldSamplesChangeNothing) {
  MasterPorts master(true);
  // The force pushes the hand back (target moving at -1 mm/s against +1 N): 1 uJ out per tick.
  const Axes3 received{-1.0, 0, 0}, rate{-1e-3, 0, 0};
  master.arrived({0.0, 0, 0});
  master.arrived({1e-6, 0, 0});
  EXPECT_NEAR(master.contact_force(received, rate, kDt)[0], -1.0, 1e-12);
  EXPECT_NEAR(master.contact_force(received, rate, kDt)[0], 0.0, 1e-12) << "spent: the damper cancels it";
  master.arrived({0.5e-6, 0, 0});  // an older sample overtaken by the newer one
  EXPECT_NEAR(master.contact_force(received, rate, kDt)[0], 0.0, 1e-12);
  // The slave restarts: its totals begin again at zero. It is not locked out by what its
  // predecessor put in and this end spent...
  master.restart();
  EXPECT_NEAR(master.contact_force(received, rate, kDt)[0], 0.0, 1e-12) << "nothing before its first sample";
  master.arrived({0.0, 0, 0});
  master.arrived({2e-6, 0, 0});
  EXPECT_NEAR(master.contact_force(received, rate, kDt)[0], -1.0, 1e-12);
  EXPECT_NEAR(master.contact_force(received, rate, kDt)[0], -1.0, 1e-12);
  // ... and what this end output before does not come back either.
  EXPECT_NEAR(master.contact_force(received, rate, kDt)[0], 0.0, 1e-12);
  EXPECT_NEAR(master.report().output_energy_J[0], 3e-6, 1e-18);
  EXPECT_GE(master.report().min_observed_J, -1e-18);
  // A tick of no time (a test's exchange(0)) books nothing and never divides by it.
  EXPECT_EQ(master.contact_force(received, rate, 0.0)[0], -1.0);
  EXPECT_EQ(SlavePorts(true).velocity({1e-3, 0, 0}, {-1.0, 0, 0}, 0.0)[0], 0.0);
  EXPECT_NEAR(master.report().output_energy_J[0], 3e-6, 1e-18);
}

TEST(PassivePorts, TheGrippersPortLetsTheJawsSqueezeOnlyWithTheEnergyTheMasterPutIn) {
  SlavePorts slave(true);
  // Closing at 1 mm/s on a part that pushes the jaws open with 1 N: 1 uJ per tick.
  EXPECT_EQ(slave.opening_rate(-1e-3, 1.0, kDt), 0.0) << "no session yet: nothing may leave";
  slave.arrived({5e-6, 5e-6, 5e-6});  // the axes' energies open the axes' sessions only
  EXPECT_EQ(slave.opening_rate(-1e-3, 1.0, kDt), 0.0);
  EXPECT_FALSE(slave.report().session_open);
  slave.arrived_gripper(0.5e-6);
  EXPECT_TRUE(slave.report().session_open);
  slave.arrived_gripper(2.0e-6);  // 1.5 uJ of the master's squeeze arrived
  EXPECT_NEAR(slave.opening_rate(-1e-3, 1.0, kDt), -1e-3, 1e-15);
  EXPECT_NEAR(slave.opening_rate(-1e-3, 1.0, kDt), -0.5e-3, 1e-15) << "the half that is left";
  EXPECT_NEAR(slave.opening_rate(-1e-3, 1.0, kDt), 0.0, 1e-15);
  // Opening, the part's push does work on the jaws: energy in, freely; free air costs nothing.
  EXPECT_NEAR(slave.opening_rate(1e-3, 1.0, kDt), 1e-3, 1e-15);
  EXPECT_NEAR(slave.opening_rate(-1e-3, 0.0, kDt), -1e-3, 1e-15);
  EXPECT_NEAR(slave.report().input_energy_J[kGripperPort], 1e-6, 1e-18);
  EXPECT_GE(slave.report().min_observed_J, -1e-18);
  // The master's end: the grip force pushing the operator's fingers open while they open is
  // energy out, let through as far as the slave's squeeze has arrived, then damped away.
  MasterPorts master(true);
  master.arrived_gripper(0.0);
  master.arrived_gripper(1e-6);
  EXPECT_NEAR(master.grip_force(1.0, 1e-3, kDt), 1.0, 1e-12);
  EXPECT_NEAR(master.grip_force(1.0, 1e-3, kDt), 0.0, 1e-12) << "spent: the damper cancels it";
  EXPECT_NEAR(master.grip_force(1.0, -1e-3, kDt), 1.0, 1e-12) << "squeezing puts energy in: passes";
  EXPECT_GE(master.report().min_observed_J, -1e-18);
  MasterPorts open(false);
  EXPECT_EQ(open.grip_force(1.0, 1e-3, kDt), 1.0);
  EXPECT_NEAR(open.report().min_observed_J, -1e-6, 1e-18);
}

// Both ends joined by emulated lines (the energies travel with the loss and jitter of the state
// they ride on), driven by random forces and velocities, with the master restarted half way;
// through an axis' port or the gripper's.
double lowest_channel_energy(bool passivity, const teleop::LinkParams& line, bool gripper) {
  const std::size_t port = gripper ? kGripperPort : 0;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto master = std::make_unique<MasterPorts>(passivity);
  SlavePorts slave(passivity);
  teleop::LinkParams back = line;
  back.seed = line.seed + 1;
  teleop::EmulatedLink forward(line, kDt), backward(back, kDt);
  double dead_master_balance = 0.0;  // the restarted master's predecessor: in - out
  double lowest = 0.0;
  for (int k = 0; k < 20000; ++k) {
    const double t = k * kDt;
    if (k == 10000) {
      const PortsReport r = master->report();
      dead_master_balance = r.input_energy_J[port] - r.output_energy_J[port];
      master = std::make_unique<MasterPorts>(passivity);
      slave.restart();
    }
    const double f = 1e-3 * u(rng), v = 1e-3 * u(rng), fs = 1e-3 * u(rng), vs = 1e-3 * u(rng);
    if (gripper) {
      master->grip_force(f, v, kDt);
      slave.opening_rate(vs, fs, kDt);
    } else {
      master->contact_force({f, 0, 0}, {v, 0, 0}, kDt);
      slave.velocity({vs, 0, 0}, {fs, 0, 0}, kDt);
    }
    forward.send({t, 0.0, master->report().input_energy_J[port]});
    backward.send({t, 0.0, slave.report().input_energy_J[port]});
    teleop::LinkSample got;
    const auto arrive = [&](auto& end, double e) {
      gripper ? end.arrived_gripper(e) : end.arrived({e, 0, 0});
    };
    if (forward.receive(t, got)) arrive(slave, got.energy_J);
    if (backward.receive(t, got)) arrive(*master, got.energy_J);
    const PortsReport m = master->report(), s = slave.report();
    const double channel = dead_master_balance + m.input_energy_J[port] - m.output_energy_J[port] +
                           s.input_energy_J[port] - s.output_energy_J[port];
    lowest = std::min(lowest, channel);
  }
  return lowest;
}

TEST(PassivePorts, TheChannelNeverCreatesEnergyWhateverTheDelayJitterLossAndRestarts) {
  for (const teleop::LinkParams& line :
       {teleop::LinkParams{0.0, 0.0, 0.0, 3}, teleop::LinkParams{0.1, 0.0, 0.0, 5},
        teleop::LinkParams{0.1, 0.02, 0.2, 7}}) {
    SCOPED_TRACE(testing::Message() << "delay " << line.delay_s << " s, jitter " << line.jitter_s
                                    << " s, loss " << line.loss);
    for (bool gripper : {false, true}) {
      SCOPED_TRACE(gripper ? "the gripper's port" : "an axis' port");
      // Powers are about 1e-6 W: 1 nJ per ms of steps. Rounding stays far below.
      const double protected_J = lowest_channel_energy(true, line, gripper);
      const double open_J = lowest_channel_energy(false, line, gripper);
      EXPECT_GE(protected_J, -1e-15);
      // A random walk of 1 nJ steps: 20 000 of them stray about 100 nJ from zero.
      EXPECT_LT(open_J, -1e-8) << "the unprotected channel creates energy";
      std::printf("lowest channel energy (%s): protected %.3g J, unprotected %.3g J\n",
                  gripper ? "gripper" : "axis", protected_J, open_J);
    }
  }
}

}  // namespace
}  // namespace mc::net
