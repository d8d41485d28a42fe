#include "microcobot/net/passive_ports.h"

#include <algorithm>

namespace mc::net {

namespace {

// The port conventions of control/passivity.h take the force the far side opposes to the
// port's motion: the contact force on the gripper points against the motion that presses it.
double opposing(double contact_N) { return -contact_N; }

template <class Controllers>
PortsReport report_of(const Controllers& pc, const EnergySession& session, double min_observed_J) {
  PortsReport r;
  for (std::size_t i = 0; i < 3; ++i) {
    r.observed_J[i] = pc[i].observed_J();
    r.dissipated_J += pc[i].dissipated_J();
    r.input_energy_J[i] = pc[i].energy().in_J;
    r.output_energy_J[i] = pc[i].energy().out_J;
  }
  r.min_observed_J = min_observed_J;
  r.session_open = session.open();
  return r;
}

}  // namespace

void EnergySession::arrived(const Axes3& peer_in_J, const Axes3& own_out_J) noexcept {
  if (!open_) {
    open_ = true;
    peer_in_J_ = peer_base_J_ = peer_in_J;
    own_base_J_ = own_out_J;
    return;
  }
  // Totals only grow: an older sample overtaken by a newer one changes nothing.
  for (std::size_t i = 0; i < 3; ++i) peer_in_J_[i] = std::max(peer_in_J_[i], peer_in_J[i]);
}

MasterPorts::MasterPorts(bool enabled)
    : pc_{control::MasterPassivityController(enabled), control::MasterPassivityController(enabled),
          control::MasterPassivityController(enabled)} {}

void MasterPorts::arrived(const Axes3& slave_in_J) noexcept {
  session_.arrived(slave_in_J, {pc_[0].energy().out_J, pc_[1].energy().out_J, pc_[2].energy().out_J});
}

Axes3 MasterPorts::contact_force(const Axes3& received_N, const Axes3& target_rate_m_s,
                                 double dt_s) noexcept {
  Axes3 out{};
  for (std::size_t i = 0; i < 3; ++i) {
    auto& pc = pc_[i];
    const double f = pc.force(opposing(received_N[i]), target_rate_m_s[i],
                              session_.remote_in_J(i, pc.energy().out_J), dt_s);
    out[i] = opposing(f);
    min_observed_J_ = std::min(min_observed_J_, pc.observed_J());
  }
  return out;
}

PortsReport MasterPorts::report() const noexcept { return report_of(pc_, session_, min_observed_J_); }

SlavePorts::SlavePorts(bool enabled)
    : pc_{control::SlavePassivityController(enabled), control::SlavePassivityController(enabled),
          control::SlavePassivityController(enabled)} {}

void SlavePorts::arrived(const Axes3& master_in_J) noexcept {
  session_.arrived(master_in_J, {pc_[0].energy().out_J, pc_[1].energy().out_J, pc_[2].energy().out_J});
}

Axes3 SlavePorts::velocity(const Axes3& asked_m_s, const Axes3& contact_N, double dt_s) noexcept {
  Axes3 out{};
  for (std::size_t i = 0; i < 3; ++i) {
    auto& pc = pc_[i];
    out[i] =
        pc.velocity(asked_m_s[i], opposing(contact_N[i]), session_.remote_in_J(i, pc.energy().out_J), dt_s);
    min_observed_J_ = std::min(min_observed_J_, pc.observed_J());
  }
  return out;
}

PortsReport SlavePorts::report() const noexcept { return report_of(pc_, session_, min_observed_J_); }

}  // namespace mc::net
