#pragma once
/// @file
/// Time-domain passivity across the two processes of a distributed platform:
/// the passivity observer and controller of teleop/passivity.h (Ryu, Artigas and Preusche's
/// time-delay form) at each end of the coupling's network channel, one port per stage axis and
/// one for the gripper.
///
/// The channel's ports are where its signals enter and leave the network, in the slave's units
/// (m, N): at the master's end the stage target's rate v goes in and the slave's contact force
/// comes out; at the slave's end the target comes out as the stage's commanded velocity and the
/// contact force goes in. The gripper's port is the same along its opening: the opening
/// target's rate against the grip force (the part pushes the jaws open with it). Each end books
/// the power through its ports, sends its input energies with its state
/// (`rt/microcobot/{master,slave}/port_energy` for the axes, `.../gripper/port_energy` for the
/// gripper, 1 kHz) and may output only the energy the other end has put in and that has arrived:
///   master: PO_m = E_in,s(t - T_b) - E_out,m(t) >= 0  (a damper on the force it hands the coupling)
///   slave:  PO_s = E_in,m(t - T_f) - E_out,s(t) >= 0  (the commanded velocity reduced)
/// whatever the delay, jitter or loss of the network: energies are running totals, so a lost or
/// late sample only delays the energy it carried, and one arriving out of order is ignored.
///
/// Sessions: a peer that falls silent and comes back (a restarted process, a link that was cut)
/// starts a new session at this end: each port's energies count from the first sample for it
/// that arrives after the return, and this end's output from then on. Each end then outputs,
/// over all its sessions, at most what the other put in over disjoint stretches of time, so the
/// channel stays passive across restarts while a restarted peer (whose totals begin again at 0)
/// is not locked out by the energy its predecessor spent. Until that first sample the port
/// outputs nothing.
///
/// Plain arithmetic on the loop: no allocation, lock or branch on the delay.

#include <array>
#include <cstddef>

#include "microcobot/teleop/passivity.h"

namespace mc::net {

using Axes3 = std::array<double, 3>;
/// The channel's ports: the stage axes x, y, z, then the gripper's opening.
inline constexpr std::size_t kPortCount = 4;
inline constexpr std::size_t kGripperPort = 3;
using PortValues = std::array<double, kPortCount>;

/// What an end's ports observed, for reports and tests.
struct PortsReport {
  PortValues observed_J{};       ///< PO of each port in the current session
  double min_observed_J = 0.0;   ///< the lowest PO of any port since the start
  double dissipated_J = 0.0;     ///< by the passivity controllers, all ports
  PortValues input_energy_J{};   ///< this end's input energies (what it sends)
  PortValues output_energy_J{};  ///< this end's output energies
  bool session_open = false;     ///< the peer's energies have arrived for every port since it (re)appeared
  /// The stage axes' input energies (the `port_energy` message).
  Axes3 axes_input_energy_J() const { return {input_energy_J[0], input_energy_J[1], input_energy_J[2]}; }
};

/// The session bookkeeping both ends share, per port.
class EnergySession {
 public:
  /// The peer (re)appeared: its energies count again from the next sample of each port.
  void restart() noexcept { open_.fill(false); }
  /// A sample of the peer's input energy into port `i` (its total); `own_out_J` this end's
  /// output total through it.
  void arrived(std::size_t i, double peer_in_J, double own_out_J) noexcept;
  /// What the controller of port `i` may count as the peer's input so that its observer reads
  /// this session's balance: the peer's input since the session opened, plus this end's output
  /// before it. Before the first sample, exactly this end's output: nothing more may leave.
  double remote_in_J(std::size_t i, double own_out_J) const noexcept {
    return open_[i] ? peer_in_J_[i] - peer_base_J_[i] + own_base_J_[i] : own_out_J;
  }
  bool open() const noexcept {
    for (bool o : open_)
      if (!o) return false;
    return true;
  }

 private:
  std::array<bool, kPortCount> open_{};
  PortValues peer_in_J_{}, peer_base_J_{}, own_base_J_{};
};

/// What both ends share: a controller per port, the sessions, the lowest observation.
template <class Controller>
class Ports {
 public:
  explicit Ports(bool enabled)
      : pc_{Controller(enabled), Controller(enabled), Controller(enabled), Controller(enabled)} {}
  /// The peer (re)appeared: a new session.
  void restart() noexcept { session_.restart(); }
  /// A sample of the peer's input energies into the axes' ports arrived.
  void arrived(const Axes3& peer_in_J) noexcept;
  /// A sample of the peer's input energy into the gripper's port arrived.
  void arrived_gripper(double peer_in_J) noexcept;
  PortsReport report() const noexcept;

 protected:
  /// The peer's input energy controller `i` may count on (EnergySession::remote_in_J).
  double remote_in_J(std::size_t i) const noexcept { return session_.remote_in_J(i, pc_[i].energy().out_J); }
  void observed(std::size_t i) noexcept;

  std::array<Controller, kPortCount> pc_;
  EnergySession session_;
  double min_observed_J_ = 0.0;
};

/// The master's end (net/remote_slave.h): the slave's contact force comes out of the channel
/// through a variable damper on the target's rate.
class MasterPorts final : public Ports<teleop::MasterPassivityController> {
 public:
  using Ports::Ports;
  /// The contact force (stage frame, N, on the gripper) to hand the coupling for one tick of
  /// `dt_s`, given the force received and the rate of the target sent last (m/s). A tick of no
  /// time (dt_s <= 0) passes the force unchanged and books nothing.
  Axes3 contact_force(const Axes3& received_N, const Axes3& target_rate_m_s, double dt_s) noexcept;
  /// The same for the gripper: the grip force (N) to hand the coupling, given the one received
  /// and the rate of the opening target sent last (m/s).
  double grip_force(double received_N, double opening_rate_m_s, double dt_s) noexcept;
};

/// The slave's end (net/remote_master.h): the commanded velocity of the stage's target comes out
/// of the channel against the contact force the environment opposes to it.
class SlavePorts final : public Ports<teleop::SlavePassivityController> {
 public:
  using Ports::Ports;
  /// The velocity to command for one tick of `dt_s` (m/s), given the one the master's target
  /// asks for and the contact force on the gripper (stage frame, N). A tick of no time: zero.
  Axes3 velocity(const Axes3& asked_m_s, const Axes3& contact_N, double dt_s) noexcept;
  /// The same for the gripper: the opening rate to command (m/s), given the one the master's
  /// opening target asks for and the grip force the part opposes to closing (N).
  double opening_rate(double asked_m_s, double grip_N, double dt_s) noexcept;
};

}  // namespace mc::net
