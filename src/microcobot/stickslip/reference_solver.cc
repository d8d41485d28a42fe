#include "microcobot/stickslip/reference_solver.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <boost/numeric/odeint.hpp>

#include "microcobot/core/error.h"

namespace mc::stickslip {

namespace {

// State: [x1a, v1a, x1b, v1b, x2a, v2a, x2b, v2b, za, zb]; positions in metres, velocities in
// m/s scaled by 1e-6 s (so that one tolerance fits both).
using OdeState = std::array<double, 10>;
constexpr double kVelScale = 1e-6;

struct Rhs {
  const StickSlipParams& p;
  const Waveform& wave;
  const PiState& pi;  // committed at the start of the current interval
  double z_ba_a, z_ba_b;

  void operator()(const OdeState& y, OdeState& dy, double t) const {
    const double uh = p.pe.static_gain_m_V *
                      pi_peek(p.hysteresis, pi, std::clamp(wave.value(t), p.drive.min_V, p.drive.max_V));
    const double phi = p.pe.gain_fraction_a;
    const double v1a = y[1] / kVelScale, v1b = y[3] / kVelScale;
    const double v1 = v1a + v1b;
    const double ca = p.friction.mass_fraction_a;
    const std::array<double, 2> c = {ca, 1.0 - ca};
    const std::array<double, 2> rho0 = {p.friction.rho0_a_N_m, p.friction.rho0_b_N_m};
    const std::array<double, 2> rho1 = {p.friction.rho1_a_N_s_m, p.friction.rho1_b_N_s_m};
    const std::array<double, 2> zba = {z_ba_a, z_ba_b};
    std::array<double, 2> f{}, zdot{};
    double ff = 0.0;
    if (p.slider.attached) {
      for (int i = 0; i < 2; ++i) {
        const double v2 = y[5 + 2 * i] / kVelScale;
        const double xdot = v1 - v2;
        const double z = y[8 + i];
        const double sgn = xdot > 0.0 ? 1.0 : (xdot < 0.0 ? -1.0 : 0.0);
        zdot[i] = xdot * friction_dz_dx(z, sgn, zba[i], zba[i] / p.friction.zba_zss_ratio);  // eq. 2.11
        f[i] = rho0[i] * z + rho1[i] * zdot[i] + p.friction.rho2_N_s_m * xdot;               // eq. 2.10
        ff += c[i] * f[i];
      }
    }
    const double m = p.pe.mass_kg;
    dy[0] = v1a;
    dy[1] =
        kVelScale *
        (p.pe.stiffness_a_N_m * phi * uh - ff - p.pe.damping_a_N_s_m * v1a - p.pe.stiffness_a_N_m * y[0]) / m;
    dy[2] = v1b;
    dy[3] = kVelScale *
            (p.pe.stiffness_b_N_m * (1.0 - phi) * uh - ff - p.pe.damping_b_N_s_m * v1b -
             p.pe.stiffness_b_N_m * y[2]) /
            m;
    for (int i = 0; i < 2; ++i) {
      const int j = 1 - i;
      if (!p.slider.attached) {
        dy[4 + 2 * i] = 0.0;
        dy[5 + 2 * i] = 0.0;
        dy[8 + i] = 0.0;
        continue;
      }
      const double force = c[i] * (f[i] + p.slider.load_force_N) +
                           p.friction.coupling_stiffness_N_m * (y[4 + 2 * j] - y[4 + 2 * i]);
      dy[4 + 2 * i] = y[5 + 2 * i] / kVelScale;
      dy[5 + 2 * i] = kVelScale * force / (c[i] * p.slider.mass_kg);
      dy[8 + i] = zdot[i];
    }
  }
};

}  // namespace

Trajectory simulate_reference(const StickSlipParams& params, const Waveform& wave, double duration_s,
                              const ReferenceOptions& options) {
  params.validate();
  wave.validate(params.drive);
  require_positive(options.rel_tol, "rel_tol");
  require_positive(options.abs_tol_m, "abs_tol_m");
  require_positive(options.sample_dt_s, "sample_dt_s");
  namespace ode = boost::numeric::odeint;
  PiState pi = make_pi_state(params.hysteresis, 0.0);
  BreakawayTable const& table = params.breakaway;
  const double f_op = wave.kind == WaveKind::kStep ? table.frequencies_Hz.front() : wave.frequency_Hz;
  const double z_ba = table.lookup(wave.amplitude_V, f_op, wave.direction);
  Rhs rhs{params, wave, pi, z_ba, z_ba * params.friction.breakaway_strain_ratio_b};
  OdeState y{};
  y[4] = y[6] = params.slider.initial_position_m;
  auto stepper =
      ode::make_controlled(options.abs_tol_m, options.rel_tol, ode::runge_kutta_dopri5<OdeState>());
  const auto n = static_cast<long>(std::llround(duration_s / options.sample_dt_s));
  Trajectory tr;
  const double ca = params.friction.mass_fraction_a;
  auto record = [&](double t) {
    tr.t_s.push_back(t);
    tr.u_V.push_back(std::clamp(wave.value(t), params.drive.min_V, params.drive.max_V));
    tr.x1_m.push_back(y[0] + y[2]);
    tr.x2_m.push_back(params.slider.attached ? ca * y[4] + (1.0 - ca) * y[6]
                                             : params.slider.initial_position_m);
  };
  record(0.0);
  double h = std::min(1e-7, options.sample_dt_s);
  for (long k = 1; k <= n; ++k) {
    const double t0 = static_cast<double>(k - 1) * options.sample_dt_s;
    const double t1 = static_cast<double>(k) * options.sample_dt_s;
    // Integrate corner to corner: U is linear, so monotone, between corners, and the PI's
    // branches are committed where U turns (the kinks also end the adaptive steps exactly).
    const DriveSegment seg = wave.segment(t0, t1 - t0);
    double ta = t0;
    for (int c = 0; c <= seg.corners; ++c) {
      const bool last = c == seg.corners;
      const double tb = last ? t1 : t0 + seg.at[static_cast<std::size_t>(c)] * (t1 - t0);
      if (tb > ta) ode::integrate_adaptive(stepper, rhs, y, ta, tb, h);
      pi_update(params.hysteresis, pi, std::clamp(wave.value(tb), params.drive.min_V, params.drive.max_V));
      ta = tb;
    }
    for (double v : y) {
      if (!std::isfinite(v))
        throw ComputationFailed("reference solver diverged (NaN/Inf) at t = " + std::to_string(t1));
    }
    record(t1);
  }
  return tr;
}

double relative_rms_error(const Trajectory& a, const Trajectory& b) {
  const std::size_t n = std::min(a.x2_m.size(), b.x2_m.size());
  require(n > 1, "trajectory", "needs at least two common samples");
  double sum = 0.0, lo = b.x2_m[0], hi = b.x2_m[0];
  for (std::size_t i = 0; i < n; ++i) {
    const double d = a.x2_m[i] - b.x2_m[i];
    sum += d * d;
    lo = std::min(lo, b.x2_m[i]);
    hi = std::max(hi, b.x2_m[i]);
  }
  require(hi > lo, "trajectory", "reference has zero range");
  return std::sqrt(sum / static_cast<double>(n)) / (hi - lo);
}

}  // namespace mc::stickslip
