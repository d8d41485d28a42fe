#include "microcobot/microworld/piezo_bender.h"

#include <algorithm>
#include <cmath>

namespace mc::microworld {

void PiezoBenderParams::validate(const char* prefix) const {
  const std::string at = std::string(prefix) + ".";
  require(std::isfinite(gain_m_V) && gain_m_V > 0.0 && gain_m_V <= 100e-6, at + "gain_m_V",
          "must be within (0, 100 um/V]", gain_m_V);
  require(std::isfinite(max_voltage_V) && max_voltage_V > 0.0 && max_voltage_V <= 1000.0,
          at + "max_voltage_V", "must be within (0, 1000] V", max_voltage_V);
  require(std::isfinite(bw_A_m_V) && bw_A_m_V >= 0.0 && bw_A_m_V < gain_m_V, at + "bw_A_m_V",
          "must be within [0, gain_m_V)", bw_A_m_V);
  require(std::isfinite(bw_beta_1_V) && bw_beta_1_V >= 0.0, at + "bw_beta_1_V", "must be >= 0", bw_beta_1_V);
  require(std::isfinite(bw_gamma_1_V) && std::abs(bw_gamma_1_V) <= bw_beta_1_V, at + "bw_gamma_1_V",
          "must be within [-bw_beta_1_V, bw_beta_1_V] (a bounded loop)", bw_gamma_1_V);
  require(std::isfinite(creep_per_decade) && creep_per_decade >= 0.0 && creep_per_decade <= 0.1,
          at + "creep_per_decade", "must be within [0, 0.1]", creep_per_decade);
  require(std::isfinite(creep_tau0_s) && creep_tau0_s > 0.0 && creep_tau0_s <= 100.0, at + "creep_tau0_s",
          "must be within (0, 100] s", creep_tau0_s);
  require(std::isfinite(mode_frequency_Hz) && mode_frequency_Hz >= 10.0 && mode_frequency_Hz <= 100e3,
          at + "mode_frequency_Hz", "must be within [10 Hz, 100 kHz]", mode_frequency_Hz);
  require(std::isfinite(mode_damping) && mode_damping > 0.0 && mode_damping <= 2.0, at + "mode_damping",
          "must be within (0, 2]", mode_damping);
}

void step_bender(const PiezoBenderParams& p, PiezoBenderState& s, double u_V, double dt_s) noexcept {
  const double u_end = std::clamp(u_V, -p.max_voltage_V, p.max_voltage_V);
  if (!(dt_s > 0.0)) return;
  const double w0 = 2.0 * M_PI * p.mode_frequency_Hz;
  const int n = std::max(1, static_cast<int>(std::ceil(dt_s * p.mode_frequency_Hz * 20.0)));
  const double h = dt_s / n;
  const double du = (u_end - s.u_V) / n;
  for (int k = 0; k < n; ++k) {
    const double u = s.u_V + du;
    // Bouc-Wen over the sub-step's voltage increment (rate-independent: dh per du).
    s.h_m += p.bw_A_m_V * du - p.bw_beta_1_V * std::abs(du) * s.h_m - p.bw_gamma_1_V * du * std::abs(s.h_m);
    s.u_V = u;
    // Creep: each first order exactly over the sub-step.
    double creep = 0.0;
    double tau = p.creep_tau0_s;
    for (double& c : s.creep_m) {
      const double target = p.creep_per_decade * p.gain_m_V * u;
      c = target + (c - target) * std::exp(-h / tau);
      creep += c;
      tau *= 10.0;
    }
    // The first mode, semi-implicit Euler (stable for w0 h < 2; here w0 h <= 2 pi / 20).
    const double drive = p.gain_m_V * u - s.h_m + creep;
    s.v_m_s += h * (w0 * w0 * (drive - s.y_m) - 2.0 * p.mode_damping * w0 * s.v_m_s);
    s.y_m += h * s.v_m_s;
  }
  s.u_V = u_end;
}

PiezoBenderState settled_bender(const PiezoBenderParams& p, double u_V) noexcept {
  PiezoBenderState s;
  const double u = std::clamp(u_V, -p.max_voltage_V, p.max_voltage_V);
  // The hysteresis along the virgin branch from 0 V to u, in 1000 increments.
  const double du = u / 1000.0;
  for (int k = 0; k < 1000; ++k)
    s.h_m += p.bw_A_m_V * du - p.bw_beta_1_V * std::abs(du) * s.h_m - p.bw_gamma_1_V * du * std::abs(s.h_m);
  s.u_V = u;
  for (double& c : s.creep_m) c = p.creep_per_decade * p.gain_m_V * u;
  s.y_m = p.gain_m_V * u - s.h_m + kCreepDecades * p.creep_per_decade * p.gain_m_V * u;
  return s;
}

}  // namespace mc::microworld
