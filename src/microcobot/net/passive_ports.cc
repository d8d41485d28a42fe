#include "microcobot/net/passive_ports.h"

#include <algorithm>

namespace mc::net {

namespace {

// The port conventions of teleop/passivity.h take the force the far side opposes to the
// port's motion: the contact force on the gripper points against the motion that presses it.
double opposing(double contact_N) { return -contact_N; }

}  // namespace

void EnergySession::arrived(std::size_t i, double peer_in_J, double own_out_J) noexcept {
  if (!open_[i]) {
    open_[i] = true;
    peer_in_J_[i] = peer_base_J_[i] = peer_in_J;
    own_base_J_[i] = own_out_J;
    return;
  }
  // Totals only grow: an older sample overtaken by a newer one changes nothing.
  peer_in_J_[i] = std::max(peer_in_J_[i], peer_in_J);
}

template <class Controller>
void Ports<Controller>::arrived(const Axes3& peer_in_J) noexcept {
  for (std::size_t i = 0; i < 3; ++i) session_.arrived(i, peer_in_J[i], pc_[i].energy().out_J);
}

template <class Controller>
void Ports<Controller>::arrived_gripper(double peer_in_J) noexcept {
  session_.arrived(kGripperPort, peer_in_J, pc_[kGripperPort].energy().out_J);
}

template <class Controller>
void Ports<Controller>::observed(std::size_t i) noexcept {
  min_observed_J_ = std::min(min_observed_J_, pc_[i].observed_J());
}

template <class Controller>
PortsReport Ports<Controller>::report() const noexcept {
  PortsReport r;
  for (std::size_t i = 0; i < kPortCount; ++i) {
    r.observed_J[i] = pc_[i].observed_J();
    r.dissipated_J += pc_[i].dissipated_J();
    r.input_energy_J[i] = pc_[i].energy().in_J;
    r.output_energy_J[i] = pc_[i].energy().out_J;
  }
  r.min_observed_J = min_observed_J_;
  r.session_open = session_.open();
  return r;
}

template class Ports<teleop::MasterPassivityController>;
template class Ports<teleop::SlavePassivityController>;

Axes3 MasterPorts::contact_force(const Axes3& received_N, const Axes3& target_rate_m_s,
                                 double dt_s) noexcept {
  if (!(dt_s > 0.0)) return received_N;  // no time, no energy (a damper over 0 s is undefined)
  Axes3 out{};
  for (std::size_t i = 0; i < 3; ++i) {
    out[i] = opposing(pc_[i].force(opposing(received_N[i]), target_rate_m_s[i], remote_in_J(i), dt_s));
    observed(i);
  }
  return out;
}

double MasterPorts::grip_force(double received_N, double opening_rate_m_s, double dt_s) noexcept {
  if (!(dt_s > 0.0)) return received_N;
  // Along the opening the grip force is the part's push on the jaws: a contact force like the
  // axes' (it opposes closing as a contact opposes pressing).
  const double out = opposing(
      pc_[kGripperPort].force(opposing(received_N), opening_rate_m_s, remote_in_J(kGripperPort), dt_s));
  observed(kGripperPort);
  return out;
}

double SlavePorts::opening_rate(double asked_m_s, double grip_N, double dt_s) noexcept {
  if (!(dt_s > 0.0)) return 0.0;
  const double out = pc_[kGripperPort].velocity(asked_m_s, opposing(grip_N), remote_in_J(kGripperPort), dt_s);
  observed(kGripperPort);
  return out;
}

Axes3 SlavePorts::velocity(const Axes3& asked_m_s, const Axes3& contact_N, double dt_s) noexcept {
  if (!(dt_s > 0.0)) return {};  // no time: nothing moves
  Axes3 out{};
  for (std::size_t i = 0; i < 3; ++i) {
    out[i] = pc_[i].velocity(asked_m_s[i], opposing(contact_N[i]), remote_in_J(i), dt_s);
    observed(i);
  }
  return out;
}

}  // namespace mc::net
