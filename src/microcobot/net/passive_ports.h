#pragma once
/// @file
/// Time-domain passivity across the two processes of a distributed platform (issue #17 point 4):
/// the passivity observer and controller of control/passivity.h (Ryu, Artigas and Preusche's
/// time-delay form) at each end of the coupling's network channel, one port per stage axis.
///
/// The channel's ports are where its signals enter and leave the network, in the slave's units
/// (m, N): at the master's end the stage target's rate v goes in and the slave's contact force
/// comes out; at the slave's end the target comes out as the stage's commanded velocity and the
/// contact force goes in. Each end books the power through its ports, sends its input energies
/// with its state (`rt/microcobot/{master,slave}/port_energy`, 1 kHz) and may output only the
/// energy the other end has put in and that has arrived:
///   master: PO_m = E_in,s(t - T_b) - E_out,m(t) >= 0  (a damper on the force it hands the coupling)
///   slave:  PO_s = E_in,m(t - T_f) - E_out,s(t) >= 0  (the commanded velocity reduced)
/// whatever the delay, jitter or loss of the network: energies are running totals, so a lost or
/// late sample only delays the energy it carried, and one arriving out of order is ignored.
///
/// Sessions: a peer that falls silent and comes back (a restarted process, a link that was cut)
/// starts a new session at this end: its energies count from the first sample that arrives after
/// the return, and this end's output from then on. Each end then outputs, over all its sessions,
/// at most what the other put in over disjoint stretches of time, so the channel stays passive
/// across restarts while a restarted peer (whose totals begin again at 0) is not locked out by
/// the energy its predecessor spent. Until that first sample the ports output nothing.
///
/// Plain arithmetic on the loop: no allocation, lock or branch on the delay.

#include <array>
#include <cstddef>

#include "microcobot/control/passivity.h"

namespace mc::net {

using Axes3 = std::array<double, 3>;

/// What an end's ports observed, for reports and tests.
struct PortsReport {
  Axes3 observed_J{};           ///< PO of each port in the current session
  double min_observed_J = 0.0;  ///< the lowest PO of any port since the start
  double dissipated_J = 0.0;    ///< by the passivity controllers, all ports
  Axes3 input_energy_J{};       ///< this end's input energies (what it sends)
  Axes3 output_energy_J{};      ///< this end's output energies
  bool session_open = false;    ///< the peer's energies have arrived since it (re)appeared
};

/// The session bookkeeping both ends share.
class EnergySession {
 public:
  /// The peer (re)appeared: its energies count again from the next sample.
  void restart() noexcept { open_ = false; }
  /// A sample of the peer's input energies (its totals); `own_out_J` this end's output totals.
  void arrived(const Axes3& peer_in_J, const Axes3& own_out_J) noexcept;
  /// What the controller of axis `i` may count as the peer's input so that its observer reads
  /// this session's balance: the peer's input since the session opened, plus this end's output
  /// before it. Before the first sample, exactly this end's output: nothing more may leave.
  double remote_in_J(std::size_t i, double own_out_J) const noexcept {
    return open_ ? peer_in_J_[i] - peer_base_J_[i] + own_base_J_[i] : own_out_J;
  }
  bool open() const noexcept { return open_; }

 private:
  bool open_ = false;
  Axes3 peer_in_J_{}, peer_base_J_{}, own_base_J_{};
};

/// What both ends share: a controller per axis, the sessions, the lowest observation.
template <class Controller>
class Ports {
 public:
  explicit Ports(bool enabled) : pc_{Controller(enabled), Controller(enabled), Controller(enabled)} {}
  /// The peer (re)appeared: a new session.
  void restart() noexcept { session_.restart(); }
  /// A sample of the peer's input energies arrived.
  void arrived(const Axes3& peer_in_J) noexcept;
  PortsReport report() const noexcept;

 protected:
  /// The peer's input energy controller `i` may count on (EnergySession::remote_in_J).
  double remote_in_J(std::size_t i) const noexcept { return session_.remote_in_J(i, pc_[i].energy().out_J); }
  void observed(std::size_t i) noexcept;

  std::array<Controller, 3> pc_;
  EnergySession session_;
  double min_observed_J_ = 0.0;
};

/// The master's end (net/remote_slave.h): the slave's contact force comes out of the channel
/// through a variable damper on the target's rate.
class MasterPorts final : public Ports<control::MasterPassivityController> {
 public:
  using Ports::Ports;
  /// The contact force (stage frame, N, on the gripper) to hand the coupling for one tick of
  /// `dt_s`, given the force received and the rate of the target sent last (m/s). A tick of no
  /// time (dt_s <= 0) passes the force unchanged and books nothing.
  Axes3 contact_force(const Axes3& received_N, const Axes3& target_rate_m_s, double dt_s) noexcept;
};

/// The slave's end (net/remote_master.h): the commanded velocity of the stage's target comes out
/// of the channel against the contact force the environment opposes to it.
class SlavePorts final : public Ports<control::SlavePassivityController> {
 public:
  using Ports::Ports;
  /// The velocity to command for one tick of `dt_s` (m/s), given the one the master's target
  /// asks for and the contact force on the gripper (stage frame, N). A tick of no time: zero.
  Axes3 velocity(const Axes3& asked_m_s, const Axes3& contact_N, double dt_s) noexcept;
};

}  // namespace mc::net
