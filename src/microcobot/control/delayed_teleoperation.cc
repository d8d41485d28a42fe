#include "microcobot/control/delayed_teleoperation.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "microcobot/control/passivity.h"
#include "microcobot/core/error.h"

namespace mc::control {

void DelayedTeleopParams::validate() const {
  require_in_range(rate_Hz, 100.0, 10000.0, "rate_Hz");
  require(substeps >= 1 && substeps <= 100, "substeps", "must be within [1, 100]", substeps);
  for (auto [v, name] : {std::pair{handle_mass_kg, "handle_mass_kg"},
                         {hand_stiffness_N_m, "hand_stiffness_N_m"},
                         {slave_mass_kg, "slave_mass_kg"},
                         {servo_stiffness_N_m, "servo_stiffness_N_m"},
                         {wall_m, "wall_m"},
                         {wall_stiffness_N_m, "wall_stiffness_N_m"},
                         {approach_speed_m_s, "approach_speed_m_s"},
                         {push_depth_m, "push_depth_m"},
                         {max_force_N, "max_force_N"},
                         {stable_excursion_m, "stable_excursion_m"}})
    require_positive(v, name);
  for (auto [v, name] : {std::pair{handle_damping_N_s_m, "handle_damping_N_s_m"},
                         {hand_damping_N_s_m, "hand_damping_N_s_m"},
                         {servo_damping_N_s_m, "servo_damping_N_s_m"}})
    require_non_negative(v, name);
  require_in_range(duration_s, 2.0, 600.0, "duration_s");
}

DelayCaseResult run_delay_case(const DelayedTeleopParams& p, const DelayCase& c, bool keep_series) {
  p.validate();
  const double T = 1.0 / p.rate_Hz, h = T / p.substeps;
  LinkParams lf{0.5 * c.delay_s, c.jitter_s, c.loss, c.seed},
      lb{0.5 * c.delay_s, c.jitter_s, c.loss, c.seed + 7919};
  EmulatedLink forward(lf, T), backward(lb, T);
  MasterPassivityController master_pc(c.passivity);
  SlavePassivityController slave_pc(c.passivity);

  double xm = 0.0, vm = 0.0;  // handle
  double xs = 0.0, vs = 0.0;  // slave
  double xsd = 0.0;           // slave's desired position (integral of the PC's velocity)
  double fm = 0.0;            // force rendered on the handle (opposing +x)
  double fe = 0.0;            // contact force at the slave
  const double target = p.wall_m + p.push_depth_m;
  const std::size_t n = static_cast<std::size_t>(std::llround(p.duration_s * p.rate_Hz));
  DelayCaseResult r;
  r.c = c;
  r.min_observed_energy_J = 0.0;
  std::vector<double> last_second;
  last_second.reserve(static_cast<std::size_t>(p.rate_Hz) + 1);
  double sq = 0.0;
  LinkSample got;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * T;
    // Master: send the handle's position and the master port's input energy.
    forward.send({t, xm, master_pc.energy().in_J});
    // Slave: the latest master sample; the velocity to reach it, limited by the slave's PC.
    double remote_master_in = 0.0, xmd = xsd;
    if (forward.receive(t, got)) {
      xmd = got.value;
      remote_master_in = got.energy_J;
    }
    const double vsd = slave_pc.velocity((xmd - xsd) / T, fe, remote_master_in, T);
    xsd += vsd * T;
    backward.send({t, fe, slave_pc.energy().in_J});
    // Master: the latest force sample through the master's PC.
    double remote_slave_in = 0.0, fr = 0.0;
    if (backward.receive(t, got)) {
      fr = got.value;
      remote_slave_in = got.energy_J;
    }
    fm = std::clamp(master_pc.force(fr, vm, remote_slave_in, T), -p.max_force_N, p.max_force_N);
    // Mechanics over the sample.
    for (int i = 0; i < p.substeps; ++i) {
      const double ts = t + i * h;
      const double hand = std::min(target, p.approach_speed_m_s * ts);
      const double hand_v = hand < target ? p.approach_speed_m_s : 0.0;
      const double fh = p.hand_stiffness_N_m * (hand - xm) + p.hand_damping_N_s_m * (hand_v - vm);
      vm += h * (fh - fm - p.handle_damping_N_s_m * vm) / p.handle_mass_kg;  // semi-implicit Euler
      xm += h * vm;
      fe = p.wall_stiffness_N_m * std::max(0.0, xs - p.wall_m);
      const double fs = p.servo_stiffness_N_m * (xsd - xs) + p.servo_damping_N_s_m * (vsd - vs);
      vs += h * (fs - fe) / p.slave_mass_kg;
      xs += h * vs;
    }
    fe = p.wall_stiffness_N_m * std::max(0.0, xs - p.wall_m);
    r.min_observed_energy_J =
        std::min({r.min_observed_energy_J, master_pc.observed_J(), slave_pc.observed_J()});
    r.max_handle_force_N = std::max(r.max_handle_force_N, std::abs(fm));
    r.max_contact_force_N = std::max(r.max_contact_force_N, fe);
    sq += (xs - xm) * (xs - xm);
    if (static_cast<double>(n - k) <= p.rate_Hz) last_second.push_back(xm);
    if (!std::isfinite(xm + xs)) break;
    if (keep_series) {
      r.t_s.push_back(t);
      r.handle_m.push_back(xm);
      r.slave_m.push_back(xs);
      r.handle_force_N.push_back(fm);
      r.contact_force_N.push_back(fe);
      r.po_master_J.push_back(master_pc.observed_J());
      r.po_slave_J.push_back(slave_pc.observed_J());
    }
  }
  const auto [lo, hi] = std::minmax_element(last_second.begin(), last_second.end());
  r.max_handle_excursion_m = last_second.empty() ? std::numeric_limits<double>::infinity() : *hi - *lo;
  r.stable = std::isfinite(r.max_handle_excursion_m) && r.max_handle_excursion_m < p.stable_excursion_m;
  r.rms_tracking_error_m = std::sqrt(sq / static_cast<double>(n));
  r.dissipated_J = master_pc.dissipated_J() + slave_pc.dissipated_J();
  return r;
}

}  // namespace mc::control
