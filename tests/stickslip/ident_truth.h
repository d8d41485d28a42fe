#pragma once
// The "other lab's axis" of the identification round trips: every identified part differs from
// the defaults (modes, asperities, mass split, PI weights, z_ba surface).
#include <cmath>

#include "microcobot/stickslip/stickslip_params.h"

namespace mc::stickslip::test {

/// The truth's break-away surface in closed form: affine in amplitude (Fig. 2.13), weakly
/// decreasing with log frequency, larger backward. ident_truth_params() samples it on a grid.
inline double ident_truth_zba(double amplitude_V, double frequency_Hz, Direction d) {
  const double k = 1.0 - 0.04 * std::log10(frequency_Hz / 50.0);
  return d == Direction::kForward ? (300e-9 + 3.0e-9 * amplitude_V) * k : (330e-9 + 2.5e-9 * amplitude_V) * k;
}

inline StickSlipParams ident_truth_params() {
  StickSlipParams p;
  const double mp = p.pe.mass_kg, ms = p.slider.mass_kg;
  const double wa = 2 * M_PI * 55e3, wb = 2 * M_PI * 104e3;
  p.pe.stiffness_a_N_m = mp * wa * wa;
  p.pe.damping_a_N_s_m = 2 * 0.06 * wa * mp;
  p.pe.stiffness_b_N_m = mp * wb * wb;
  p.pe.damping_b_N_s_m = 2 * 0.05 * wb * mp;
  p.pe.gain_fraction_a = 0.6;
  p.pe.static_gain_m_V = 12e-9;
  const double fa = 2 * M_PI * 520.0, fb = 2 * M_PI * 1450.0;
  p.friction.rho0_a_N_m = ms * fa * fa;
  p.friction.rho1_a_N_s_m = 2 * 0.25 * fa * ms;
  p.friction.rho0_b_N_m = ms * fb * fb;
  p.friction.rho1_b_N_s_m = 2 * 0.04 * fb * ms;
  p.friction.mass_fraction_a = 0.4;
  // PI: a softer linear part and a slower decay than the defaults.
  for (std::size_t i = 0; i < p.hysteresis.size(); ++i) {
    p.hysteresis.weights[i] = i == 0 ? 0.7 : 0.02 * std::exp(-2.0 * static_cast<double>(i) / 35.0);
  }
  const double top = pi_loading_curve(p.hysteresis, 100.0);
  for (double& w : p.hysteresis.weights) w *= 100.0 / top;
  // z_ba: affine in amplitude (Fig. 2.13), weakly decreasing with frequency, larger backward.
  BreakawayTable& t = p.breakaway;
  t.amplitudes_V = {0, 20, 40, 60, 80, 100};
  t.frequencies_Hz = {50, 200, 1000, 2000};
  t.forward_m.clear();
  t.backward_m.clear();
  for (double a : t.amplitudes_V) {
    std::vector<double> f, b;
    for (double fr : t.frequencies_Hz) {
      f.push_back(ident_truth_zba(a, fr, Direction::kForward));
      b.push_back(ident_truth_zba(a, fr, Direction::kBackward));
    }
    t.forward_m.push_back(f);
    t.backward_m.push_back(b);
  }
  p.validate();
  return p;
}

}  // namespace mc::stickslip::test
