#include "microcobot/teleop/delayed_teleoperation.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "microcobot/core/error.h"
#include "microcobot/core/rng.h"
#include "microcobot/teleop/model_mediated_master.h"
#include "microcobot/teleop/passivity.h"

namespace mc::teleop {

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
  require_in_range(wall_exponent, 1.0, 3.0, "wall_exponent");
  require(std::isfinite(settled_force_tolerance) && settled_force_tolerance > 0.0 &&
              settled_force_tolerance < 1.0,
          "settled_force_tolerance", "must be within (0, 1)", settled_force_tolerance);
  require_non_negative(master_damping_N_s_m, "master_damping_N_s_m");
  mmt.estimator.validate();
  require_in_range(mmt.time_constant_s, 0.0, 10.0, "mmt.time_constant_s");
  require_positive(mmt.prior_stiffness_N_m, "mmt.prior_stiffness_N_m");
  require(std::isfinite(mmt.prior_margin_m) && mmt.prior_margin_m >= 0.0 && mmt.prior_margin_m < wall_m,
          "mmt.prior_margin_m", "must be within [0, wall_m)", mmt.prior_margin_m);
  require_non_negative(mmt.force_noise_N, "mmt.force_noise_N");
}

double DelayedTeleopParams::wall_force_N(double depth_m) const noexcept {
  if (depth_m <= 0.0) return 0.0;
  constexpr double kReferenceDepth_m = 1e-3;
  return wall_stiffness_N_m * depth_m *
         (wall_exponent == 1.0 ? 1.0 : std::pow(depth_m / kReferenceDepth_m, wall_exponent - 1.0));
}

double DelayedTeleopParams::steady_contact_force_N() const {
  // The hand's spring, the servo and the wall in series, every one relaxed at first touch: at a
  // force F the slave is at depth d(F) = push_depth - F/k_h - F/k_p, and the wall must give F
  // there. wall_force_N(d(F)) - F falls with F from > 0 at F = 0 to < 0 where d = 0: bisection.
  const double k_hp = 1.0 / (1.0 / hand_stiffness_N_m + 1.0 / servo_stiffness_N_m);
  double lo = 0.0, hi = push_depth_m * k_hp;
  for (int i = 0; i < 200 && hi - lo > 1e-15 * hi; ++i) {
    const double f = 0.5 * (lo + hi);
    (wall_force_N(push_depth_m - f / k_hp) > f ? lo : hi) = f;
  }
  return 0.5 * (lo + hi);
}

const char* to_string(Scheme s) {
  switch (s) {
    case Scheme::kNone:
      return "none";
    case Scheme::kTdpa:
      return "tdpa";
    case Scheme::kMmt:
      return "mmt";
  }
  return "?";
}

Scheme scheme_from_string(const std::string& name) {
  for (Scheme s : {Scheme::kNone, Scheme::kTdpa, Scheme::kMmt})
    if (name == to_string(s)) return s;
  throw InvalidParams("scheme", "must be none, tdpa or mmt, got '" + name + "'");
}

DelayCaseResult run_delay_case(const DelayedTeleopParams& p, const DelayCase& c, bool keep_series) {
  p.validate();
  require(std::isfinite(c.wall_prior_error_m) && std::abs(c.wall_prior_error_m) < p.wall_m,
          "wall_prior_error_m", "must be finite and smaller than wall_m", c.wall_prior_error_m);
  const double T = 1.0 / p.rate_Hz, h = T / p.substeps;
  LinkParams lf{0.5 * c.delay_s, c.jitter_s, c.loss, c.seed},
      lb{0.5 * c.delay_s, c.jitter_s, c.loss, c.seed + 7919};
  const bool tdpa = c.scheme == Scheme::kTdpa, mmt = c.scheme == Scheme::kMmt;
  EmulatedLink forward(lf, T), backward(lb, T);
  EmulatedLinkOf<ContactModel> model_link(lb, T);  // mmt: the slave's contact model, back
  MasterPassivityController master_pc(tdpa);
  SlavePassivityController slave_pc(tdpa);
  // The model before any contact: where the microworld's geometry puts the wall (less its
  // uncertainty: see MmtSettings::prior_margin_m), the material's nominal stiffness.
  const ContactModel prior{0.0, p.wall_m + c.wall_prior_error_m - p.mmt.prior_margin_m,
                           p.mmt.prior_stiffness_N_m};
  ContactEstimator estimator(p.mmt.estimator, prior);
  ModelMediatedMaster model_master(
      {p.mmt.time_constant_s, p.servo_stiffness_N_m, p.max_force_N, p.mmt.passivity}, prior);
  Rng sensor(c.seed + 104729);

  double xm = 0.0, vm = 0.0;  // handle
  double xs = 0.0, vs = 0.0;  // slave
  double xsd = 0.0;           // slave's desired position (integral of the PC's velocity)
  double fm = 0.0;            // force rendered on the handle (opposing +x)
  double fe = 0.0;            // contact force at the slave
  const double target = p.wall_m + p.push_depth_m, f_steady = p.steady_contact_force_N();
  const std::size_t n = static_cast<std::size_t>(std::llround(p.duration_s * p.rate_Hz));
  const std::size_t last_second_from = n - std::min(n, static_cast<std::size_t>(std::llround(p.rate_Hz)));
  DelayCaseResult r;
  r.c = c;
  r.steady_contact_force_N = f_steady;
  r.passivity = tdpa || (mmt && p.mmt.passivity);
  r.min_observed_energy_J = 0.0;
  std::vector<double> xm_series, fe_series;  // for the settling time
  xm_series.reserve(n);
  fe_series.reserve(n);
  double sq = 0.0, f_sum = 0.0;
  LinkSample got;
  ContactModel got_model;
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
    if (mmt) {
      // The slave fits its contact model on what it measures (position, force sensor) and sends it.
      estimator.update(xs, fe + p.mmt.force_noise_N * sensor.normal());
      ContactModel m = estimator.model();
      m.sent_s = t;
      model_link.send(m);
      if (model_link.receive(t, got_model)) model_master.receive(got_model);
    }
    // Master: the latest force sample through the master's PC (none, tdpa).
    double remote_slave_in = 0.0, fr = 0.0;
    if (backward.receive(t, got)) {
      fr = got.value;
      remote_slave_in = got.energy_J;
    }
    if (!mmt) fm = std::clamp(master_pc.force(fr, vm, remote_slave_in, T), -p.max_force_N, p.max_force_N);
    // Mechanics over the sample; the model-mediated master renders its model at this rate.
    for (int i = 0; i < p.substeps; ++i) {
      const double ts = t + i * h;
      if (mmt) fm = model_master.force(xm, vm, h);
      const double hand = std::min(target, p.approach_speed_m_s * ts);
      const double hand_v = hand < target ? p.approach_speed_m_s : 0.0;
      const double fh = p.hand_stiffness_N_m * (hand - xm) + p.hand_damping_N_s_m * (hand_v - vm);
      const double fd = p.master_damping_N_s_m * vm;
      vm += h * (fh - fm - fd - p.handle_damping_N_s_m * vm) / p.handle_mass_kg;  // semi-implicit Euler
      xm += h * vm;
      fe = p.wall_force_N(xs - p.wall_m);
      const double fs = p.servo_stiffness_N_m * (xsd - xs) + p.servo_damping_N_s_m * (vsd - vs);
      vs += h * (fs - fe) / p.slave_mass_kg;
      xs += h * vs;
    }
    fe = p.wall_force_N(xs - p.wall_m);
    const double po_m = mmt ? model_master.observed_J() : master_pc.observed_J();
    const double po_s = mmt ? 0.0 : slave_pc.observed_J();
    r.min_observed_energy_J = std::min({r.min_observed_energy_J, po_m, po_s});
    r.max_handle_force_N = std::max(r.max_handle_force_N, std::abs(fm));
    r.max_contact_force_N = std::max(r.max_contact_force_N, fe);
    sq += (xs - xm) * (xs - xm);
    xm_series.push_back(xm);
    fe_series.push_back(fe);
    if (k >= last_second_from) {
      f_sum += fe;
      r.contact_force_max_error = std::max(r.contact_force_max_error, std::abs(fe - f_steady) / f_steady);
    }
    if (!std::isfinite(xm + xs)) break;
    if (keep_series) {
      r.t_s.push_back(t);
      r.handle_m.push_back(xm);
      r.slave_m.push_back(xs);
      r.handle_force_N.push_back(fm);
      r.contact_force_N.push_back(fe);
      r.po_master_J.push_back(po_m);
      r.po_slave_J.push_back(po_s);
    }
  }
  const double inf = std::numeric_limits<double>::infinity();
  const bool finished = xm_series.size() == n && std::isfinite(xm_series.back());
  if (finished) {
    const auto [lo, hi] = std::minmax_element(
        xm_series.begin() + static_cast<std::ptrdiff_t>(last_second_from), xm_series.end());
    r.max_handle_excursion_m = *hi - *lo;
    r.contact_force_mean_N = f_sum / static_cast<double>(n - last_second_from);
  } else {
    r.max_handle_excursion_m = r.contact_force_max_error = r.contact_force_mean_N = inf;
  }
  r.stable = std::isfinite(r.max_handle_excursion_m) && r.max_handle_excursion_m < p.stable_excursion_m;
  r.settled = r.stable && r.contact_force_max_error <= p.settled_force_tolerance;
  // Settling time: after the last sample outside the band (force within tolerance of its steady
  // value, handle within half the stable excursion of where it ends).
  r.settling_time_s = inf;
  if (r.settled) {
    std::size_t k = n;
    while (k > 0 && std::abs(fe_series[k - 1] - f_steady) <= p.settled_force_tolerance * f_steady &&
           std::abs(xm_series[k - 1] - xm_series.back()) <= 0.5 * p.stable_excursion_m)
      --k;
    if (k < n) r.settling_time_s = static_cast<double>(k) * T;
  }
  r.rms_tracking_error_m = std::sqrt(sq / static_cast<double>(n));
  r.dissipated_J = mmt ? model_master.dissipated_J() : master_pc.dissipated_J() + slave_pc.dissipated_J();
  r.final_model_wall_m = model_master.model().wall_m;
  r.final_model_stiffness_N_m = model_master.model().stiffness_N_m;
  return r;
}

}  // namespace mc::teleop
