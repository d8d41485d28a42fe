#include "microcobot/stickslip/actuator.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "microcobot/core/error.h"

namespace mc::stickslip {

ActuatorModel::ActuatorModel(StickSlipParams params) : ActuatorModel(params, params.integrator.dt_s) {}

ActuatorModel::ActuatorModel(StickSlipParams params, double dt_s) : p_(std::move(params)), dt_(dt_s) {
  p_.validate();
  require(std::isfinite(dt_s) && dt_s > 0.0 && dt_s <= 1e-4, "integrator.dt_s", "must be in (0, 1e-4] s",
          dt_s);
  substeps_ = p_.integrator.substeps;
  c_ = {p_.friction.mass_fraction_a, 1.0 - p_.friction.mass_fraction_a};
  rho0_ = {p_.friction.rho0_a_N_m, p_.friction.rho0_b_N_m};
  rho1_ = {p_.friction.rho1_a_N_s_m, p_.friction.rho1_b_N_s_m};
  for (std::size_t i = 0; i < 2; ++i) inv_m_[i] = 1.0 / (c_[i] * p_.slider.mass_kg);
  const double phi = p_.pe.gain_fraction_a;
  ka_ = p_.pe.stiffness_a_N_m * phi;
  kb_ = p_.pe.stiffness_b_N_m * (1.0 - phi);
  inv_ratio_ = 1.0 / p_.friction.zba_zss_ratio;
  inv_ka_ = 1.0 / p_.pe.stiffness_a_N_m;
  inv_kb_ = 1.0 / p_.pe.stiffness_b_N_m;
  inv_wa_ = std::sqrt(p_.pe.mass_kg * inv_ka_);
  inv_wb_ = std::sqrt(p_.pe.mass_kg * inv_kb_);
  ringing_sq_ = p_.integrator.substep_ringing_m * p_.integrator.substep_ringing_m;
  full_ = constants(dt_);
  sub_ = constants(dt_ / substeps_);
  lo_ = -0.5 * p_.slider.stroke_m;
  hi_ = 0.5 * p_.slider.stroke_m;
}

ActuatorState ActuatorModel::initial_state() const {
  ActuatorState s;
  s.pi = make_pi_state(p_.hysteresis, 0.0);
  s.x2_m = {p_.slider.initial_position_m, p_.slider.initial_position_m};
  set_operating_point(s, p_.breakaway.amplitudes_V.front(), p_.breakaway.frequencies_Hz.front(),
                      Direction::kForward);
  return s;
}

void ActuatorModel::set_operating_point(ActuatorState& s, double amplitude_V, double frequency_Hz,
                                        Direction direction) const noexcept {
  s.z_ba_m = p_.breakaway.lookup(amplitude_V, frequency_Hz, direction);
}

namespace {

/// Verlet's discrete frequency is (2/h) asin(omega h / 2); pre-warping the contact stiffness by
/// sinc^2(omega h / 2) makes the stick-phase modes (eq. 2.20-2.21 on the slider) ring at their
/// exact frequency, which removes the phase drift of the lightly damped 1.6 kHz mode.
double prewarp(double rho0, double slider_mass, double h) noexcept {
  const double half = 0.5 * std::sqrt(rho0 / slider_mass) * h;
  if (half >= 0.5)
    return rho0;  // far from the accurate regime: no correction (and no masking
                  // of an unstable step, omega h > 2, which must still diverge)
  const double sinc = std::sin(half) / half;
  return rho0 * sinc * sinc;
}

/// Corners closer than this fraction of a sub-step to a grid point are moved onto it: the shift
/// (< 1.3e-10 s at the default step) is far below the drive's time scales and saves a split.
constexpr double kCornerSnap = 1e-4;

}  // namespace

ActuatorModel::StepConstants ActuatorModel::constants(double h) const noexcept {
  StepConstants k;
  k.h = h;
  k.inv_h = 1.0 / h;
  k.ma = ModeDiscretization::make(p_.pe.mass_kg, p_.pe.damping_a_N_s_m, p_.pe.stiffness_a_N_m, h);
  k.mb = ModeDiscretization::make(p_.pe.mass_kg, p_.pe.damping_b_N_s_m, p_.pe.stiffness_b_N_m, h);
  for (std::size_t i = 0; i < 2; ++i) k.rho0[i] = prewarp(rho0_[i], p_.slider.mass_kg, h);
  return k;
}

void ActuatorModel::step(ActuatorState& s, double u_V) const noexcept { step(s, DriveSegment::to(u_V)); }

void ActuatorModel::step(ActuatorState& s, const DriveSegment& drive) const noexcept {
  // The path's knots: its corners, then the end (voltages clamped to the amplifier's range).
  std::array<double, DriveSegment::kMaxCorners + 1> knot_at{}, knot_u{};
  const int knots = std::min(drive.corners, DriveSegment::kMaxCorners) + 1;
  double variation = 0.0, prev = s.u_V;
  for (int j = 0; j < knots; ++j) {
    const auto jj = static_cast<std::size_t>(j);
    const bool last = j == knots - 1;
    knot_at[jj] = last ? 1.0 : drive.at[jj];
    knot_u[jj] = std::clamp(last ? drive.end_V : drive.u_V[jj], p_.drive.min_V, p_.drive.max_V);
    if (!(knot_u[jj] == knot_u[jj])) knot_u[jj] = prev;  // NaN: hold (the caller faults on it)
    variation += std::abs(knot_u[jj] - prev);
    prev = knot_u[jj];
  }
  // Sub-step only while the contact may leave the elastic phase: an abrupt drive edge, or a
  // strain that the step's predicted relative motion carries outward beyond frac * z_ba.
  bool active = variation > p_.integrator.substep_edge_V;
  if (!active) {
    // The PE rings (an edge's 64/120 kHz transient): each mode's distance from its static
    // equilibrium under the present forces, as an amplitude (position and velocity / omega).
    const double ff = p_.slider.attached ? s.friction_N : 0.0;
    const double ea = s.x1a_m - (ka_ * s.uh_m - ff) * inv_ka_;
    const double eb = s.x1b_m - (kb_ * s.uh_m - ff) * inv_kb_;
    const double va = s.v1a_m_s * inv_wa_, vb = s.v1b_m_s * inv_wb_;
    active = ea * ea + va * va > ringing_sq_ || eb * eb + vb * vb > ringing_sq_;
  }
  if (!active && p_.slider.attached) {
    const double frac = p_.integrator.substep_strain_fraction;
    const double v1 = s.v1a_m_s + s.v1b_m_s;
    const double zba[2] = {s.z_ba_m, s.z_ba_m * p_.friction.breakaway_strain_ratio_b};
    for (int i = 0; i < 2 && !active; ++i) {
      const double dx = (v1 - s.v2_m_s[i]) * dt_;
      const double z_pred = s.z_m[i] + dx;
      active = std::abs(z_pred) > frac * zba[i] && (z_pred > 0.0) == (dx > 0.0);
    }
  }
  const int n = active ? substeps_ : 1;
  const StepConstants& grid = n == 1 ? full_ : sub_;
  const double g = p_.pe.static_gain_m_V;
  if (knots == 1) {
    // No corner: the PI once at the end (eq. 2.5), g H(U) linear over the step (first-order hold).
    const double uh = g * pi_update(p_.hysteresis, s.pi, knot_u[0]);
    s.u_V = knot_u[0];
    const double uh0 = s.uh_m;
    if (n == 1) {
      substep(s, uh, full_);
      return;
    }
    for (int k = 1; k <= n; ++k) substep(s, uh0 + (uh - uh0) * static_cast<double>(k) / n, sub_);
    return;
  }
  // Corners near a grid point move onto it; the others split the sub-step that holds them.
  const double nd = static_cast<double>(n);
  for (int j = 0; j + 1 < knots; ++j) {
    const auto jj = static_cast<std::size_t>(j);
    const double grid_at = std::round(knot_at[jj] * nd) / nd;
    if (std::abs(knot_at[jj] - grid_at) * nd < kCornerSnap) knot_at[jj] = grid_at;
  }
  // Walk the knots: the PI is evaluated exactly at each (a corner is where U turns, where the
  // hysteresis branches), g H(U) is linear in time between them, and the path is cut at every
  // grid point and every knot.
  double a = 0.0;         // start of the next piece (fraction of the step)
  int next_grid = 1;      // index of the next grid point
  double knot0_at = 0.0;  // the previous knot and its g H(U)
  double knot0_uh = s.uh_m;
  for (int j = 0; j < knots; ++j) {
    const auto jj = static_cast<std::size_t>(j);
    const double knot1_at = knot_at[jj];
    const double knot1_uh = g * pi_update(p_.hysteresis, s.pi, knot_u[jj]);
    s.u_V = knot_u[jj];
    while (a < knot1_at) {
      const double grid_b = static_cast<double>(next_grid) / nd;
      const bool on_grid = grid_b <= knot1_at;
      const double b = on_grid ? grid_b : knot1_at;
      const bool whole = on_grid && a == static_cast<double>(next_grid - 1) / nd;
      const double uh = b == knot1_at
                            ? knot1_uh
                            : knot0_uh + (knot1_uh - knot0_uh) * (b - knot0_at) / (knot1_at - knot0_at);
      if (whole) {
        substep(s, uh, grid);
      } else {
        substep(s, uh, constants((b - a) * dt_));
      }
      a = b;
      if (on_grid) ++next_grid;
    }
    knot0_at = knot1_at;
    knot0_uh = knot1_uh;
  }
}

bool ActuatorModel::at_rest(const ActuatorState& s) const noexcept {
  constexpr double kRest_m = 1e-12, kRest_m_s = 1e-9;  // a picometre; a picometre per millisecond
  const double ff = p_.slider.attached ? s.friction_N : 0.0;
  const double ea = s.x1a_m - (ka_ * s.uh_m - ff) * inv_ka_;
  const double eb = s.x1b_m - (kb_ * s.uh_m - ff) * inv_kb_;
  const double va = s.v1a_m_s * inv_wa_, vb = s.v1b_m_s * inv_wb_;
  const double rest_sq = kRest_m * kRest_m;
  if (ea * ea + va * va > rest_sq || eb * eb + vb * vb > rest_sq) return false;
  for (std::size_t i = 0; i < 2; ++i)
    if (std::abs(s.v2_m_s[i]) > kRest_m_s || std::abs(s.a2_m_s2[i]) * dt_ > kRest_m_s) return false;
  return !s.diverged;
}

void ActuatorModel::substep(ActuatorState& s, double uh, const StepConstants& k) const noexcept {
  // A sub-step is one chain of dependent operations (PE -> relative motion -> strain -> friction
  // -> velocity -> next sub-step), so it is latency-bound: no division by a constant (reciprocals
  // of h and of the part masses), the friction reaction enters the PE step last, and eq. 2.12's
  // constants are computed once per strain update (docs/benchmarks.md).
  const double h = k.h;
  // 2. PE modes (eq. 2.1-2.2): force = K_pi * (share of g H(U)) - F_f.
  const double ff = p_.slider.attached ? s.friction_N : 0.0;
  const double x1_old = s.x1_m();
  k.ma.step_with_reaction(s.x1a_m, s.v1a_m_s, ka_ * s.uh_m, ka_ * uh, ff);
  k.mb.step_with_reaction(s.x1b_m, s.v1b_m_s, kb_ * s.uh_m, kb_ * uh, ff);
  s.uh_m = uh;
  s.t_s += h;
  const double x1_new = s.x1_m();
  if (!p_.slider.attached) {
    s.friction_N = 0.0;
    if (!std::isfinite(x1_new)) s.diverged = true;
    return;
  }
  // 3. Slider parts (eq. 2.8 per asperity, eq. 2.20-2.21) by velocity Verlet.
  const std::array<double, 2> z_ba = {s.z_ba_m, s.z_ba_m * p_.friction.breakaway_strain_ratio_b};
  const double kc = p_.friction.coupling_stiffness_N_m;
  std::array<double, 2> x_new{};
  for (std::size_t i = 0; i < 2; ++i) {
    x_new[i] = s.x2_m[i] + s.v2_m_s[i] * h + 0.5 * s.a2_m_s2[i] * h * h;
  }
  // Friction (eq. 2.10-2.11): F = rho0 z + (rho1 phi + rho2)(x1' - x2') with phi = dz/dx. The
  // velocity update takes the step's impulse: the elastic part rho0 z (and the coupling, the load)
  // by the trapezoid of its ends (Verlet), the velocity-dependent part with the PE's *mean*
  // velocity over this step (its 64/120 kHz ringing averaged, not sampled: aliased, at the step
  // rate) against the trapezoid of x2' (implicit, second order). The end-of-step force is what the
  // PE feels and what the next position prediction uses. (The trapezoid of end-of-step forces, each
  // with its own step's mean PE velocity, would make the damping's drive lag half a step, up to
  // 2.7 % of the step of fast backward drives.)
  const double v1_mean = (x1_new - x1_old) * k.inv_h;
  const double load = p_.slider.load_force_N;
  const double rho2 = p_.friction.rho2_N_s_m;
  const std::array<double, 2> x_old = s.x2_m;
  double total = 0.0;
  for (std::size_t i = 0; i < 2; ++i) {
    const std::size_t j = 1 - i;
    const double dx = (x1_new - x1_old) - (x_new[i] - x_old[i]);
    const double zss = z_ba[i] * inv_ratio_;
    const double z_new = advance_strain(s.z_m[i], dx, z_ba[i], zss);
    const double slope = friction_dz_dx(z_new, dx > 0.0 ? 1.0 : (dx < 0.0 ? -1.0 : 0.0), z_ba[i], zss);
    const double damp = rho1_[i] * slope + rho2;  // N s/m on the relative velocity
    const double inv_m = inv_m_[i];
    const double elastic_old = c_[i] * (k.rho0[i] * s.z_m[i] + load) + kc * (x_old[j] - x_old[i]);
    const double elastic_new = c_[i] * (k.rho0[i] * z_new + load) + kc * (x_new[j] - x_new[i]);
    // m (v - v0) = h (elastic_old + elastic_new) / 2 + h c damp (v1_mean - (v0 + v) / 2)
    const double cd = c_[i] * damp * inv_m * h;
    const double v =
        (s.v2_m_s[i] + 0.5 * h * inv_m * (elastic_old + elastic_new) + cd * (v1_mean - 0.5 * s.v2_m_s[i])) /
        (1.0 + 0.5 * cd);
    const double f = k.rho0[i] * z_new + damp * (v1_mean - v);
    const double a_new = (c_[i] * (f + load) + kc * (x_new[j] - x_new[i])) * inv_m;
    s.z_m[i] = z_new;
    s.f_N[i] = f;
    total += c_[i] * f;
    double x = x_new[i];
    double v_out = v;
    // 4. End stops: inelastic, unconditionally stable.
    if (x > hi_) {
      x = hi_;
      v_out = std::min(v_out, 0.0);
    } else if (x < lo_) {
      x = lo_;
      v_out = std::max(v_out, 0.0);
    }
    s.x2_m[i] = x;
    s.v2_m_s[i] = v_out;
    s.a2_m_s2[i] = a_new;
  }
  s.friction_N = total;
  if (!std::isfinite(s.x2_m[0] + s.x2_m[1] + x1_new + total)) s.diverged = true;
}

double ActuatorModel::slider_position(const ActuatorState& s) const noexcept {
  return p_.slider.attached ? c_[0] * s.x2_m[0] + c_[1] * s.x2_m[1] : p_.slider.initial_position_m;
}

double ActuatorModel::slider_velocity(const ActuatorState& s) const noexcept {
  return p_.slider.attached ? c_[0] * s.v2_m_s[0] + c_[1] * s.v2_m_s[1] : 0.0;
}

void simulate_each(const ActuatorModel& m, const Waveform& wave, double duration_s, int record_every,
                   ActuatorState& state, const std::function<void(const ActuatorState&)>& on_sample) {
  require(std::isfinite(duration_s) && duration_s > 0.0, "duration_s", "must be > 0", duration_s);
  require(record_every >= 1, "record_every", "must be >= 1", record_every);
  wave.validate(m.params().drive);
  require(wave.kind == WaveKind::kStep || wave.frequency_Hz * m.dt_s() <= 1.0, "frequency_Hz",
          "the drive's period must be at least one model step (integrator.dt_s)", wave.frequency_Hz);
  // A step has no frequency: its break-away strain is the table's quasi-static end.
  const double f_op =
      wave.kind == WaveKind::kStep ? m.params().breakaway.frequencies_Hz.front() : wave.frequency_Hz;
  m.set_operating_point(state, wave.amplitude_V, f_op, wave.direction);
  const auto steps = static_cast<long>(std::llround(duration_s / m.dt_s()));
  on_sample(state);
  for (long k = 1; k <= steps; ++k) {
    m.step(state, wave.segment(static_cast<double>(k - 1) * m.dt_s(), m.dt_s()));
    if (state.diverged) {
      throw ComputationFailed("stick-slip simulation diverged (NaN/Inf) at t = " + std::to_string(state.t_s) +
                              " s; reduce integrator.dt_s or check the parameters");
    }
    if (k % record_every == 0) on_sample(state);
  }
}

Trajectory simulate(const ActuatorModel& m, const Waveform& wave, double duration_s, int record_every,
                    ActuatorState* state) {
  require(std::isfinite(duration_s) && duration_s > 0.0, "duration_s", "must be > 0", duration_s);
  require(record_every >= 1, "record_every", "must be >= 1", record_every);
  ActuatorState local = state ? *state : m.initial_state();
  Trajectory tr;
  const auto n_rec = static_cast<std::size_t>(std::llround(duration_s / m.dt_s()) / record_every + 2);
  tr.t_s.reserve(n_rec);
  tr.u_V.reserve(n_rec);
  tr.x1_m.reserve(n_rec);
  tr.x2_m.reserve(n_rec);
  simulate_each(m, wave, duration_s, record_every, local, [&](const ActuatorState& s) {
    tr.t_s.push_back(s.t_s);
    tr.u_V.push_back(s.u_V);
    tr.x1_m.push_back(s.x1_m());
    tr.x2_m.push_back(m.slider_position(s));
  });
  if (state) *state = local;
  return tr;
}

}  // namespace mc::stickslip
