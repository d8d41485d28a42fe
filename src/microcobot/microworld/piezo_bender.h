#pragma once
/// @file
/// One piezoelectric bender (a bimorph cantilever driven by a voltage, thesis §1.2.1, Fig. 1.17):
/// the axis of one finger of the 4-DOF PiezoGripper (bender_fingers.h). Its tip deflection y
/// follows the structure of Rakotondrabe, Clévy & Lutz, "Complete open loop control of
/// hysteretic, creeped, and oscillating piezoelectric cantilevers", IEEE Trans. Automation Science
/// and Engineering 7(3), 2010: a static hysteresis, a linear creep and the first bending mode in
/// cascade,
///
///     y_s = d u - h,        dh/dt = A du/dt - beta |du/dt| h - gamma du/dt |h|   (Bouc-Wen)
///     dc_i/dt = (k_i d u - c_i) / tau_i,   i = 1..4                             (creep)
///     y'' + 2 zeta w0 y' + w0^2 y = w0^2 (y_s + sum_i c_i)                       (first mode)
///
/// with u the drive voltage (clamped to +-max_voltage_V), d the static gain, h the Bouc-Wen
/// hysteresis state (Rakotondrabe, "Bouc-Wen modeling and inverse multiplicative structure to
/// compensate hysteresis nonlinearity in piezoelectric actuators", IEEE T-ASE 8(2), 2011), and the
/// creep a sum of first orders whose weights k_i give k per decade of time from tau_1 to tau_4
/// (the logarithmic creep of PZT: docs/model.md). Parameters and their sources:
/// docs/parameters.md ("PiezoGripper benders").

#include <array>

#include "microcobot/core/params.h"

namespace mc::microworld {

struct PiezoBenderParams {
  double gain_m_V = 1.0e-6;      ///< d: the static deflection per volt (without hysteresis, creep)
  double max_voltage_V = 150.0;  ///< the drive's range +-max_voltage_V
  /// Bouc-Wen: A [m/V], beta and gamma [1/V]. The defaults give a loop whose widest opening is
  /// 14 % of the +-150 V cycle's stroke (docs/model.md).
  double bw_A_m_V = 0.35e-6;
  double bw_beta_1_V = 0.01;
  double bw_gamma_1_V = 0.004;
  /// The creep's share per decade of time, over four decades from creep_tau0_s.
  double creep_per_decade = 0.015;
  double creep_tau0_s = 0.3;
  double mode_frequency_Hz = 1000.0;  ///< the first bending mode
  double mode_damping = 0.05;         ///< its damping ratio

  template <class V>
  void visit(V& v) {
    v("gain_m_V", gain_m_V);
    v("max_voltage_V", max_voltage_V);
    v("bw_A_m_V", bw_A_m_V);
    v("bw_beta_1_V", bw_beta_1_V);
    v("bw_gamma_1_V", bw_gamma_1_V);
    v("creep_per_decade", creep_per_decade);
    v("creep_tau0_s", creep_tau0_s);
    v("mode_frequency_Hz", mode_frequency_Hz);
    v("mode_damping", mode_damping);
  }
  /// Throws mc::InvalidParams naming the field (under `prefix`).
  void validate(const char* prefix = "bender") const;
};

/// The creep's decades (first orders at tau0, 10 tau0, 100 tau0, 1000 tau0).
inline constexpr int kCreepDecades = 4;

struct PiezoBenderState {
  double u_V = 0.0;  ///< the last drive voltage applied
  double h_m = 0.0;  ///< Bouc-Wen hysteresis
  std::array<double, kCreepDecades> creep_m{};
  double y_m = 0.0, v_m_s = 0.0;  ///< the tip's deflection and speed (the first mode)
};

/// The deflection the bender would settle to at `u` without hysteresis or creep: d u.
inline double static_deflection_m(const PiezoBenderParams& p, double u_V) noexcept {
  return p.gain_m_V * u_V;
}

/// Advances the bender over `dt_s` with the drive ramped linearly from s.u_V to `u_V` (clamped
/// to the range), in sub-steps of at most a twentieth of the mode's period. Real-time safe.
void step_bender(const PiezoBenderParams& p, PiezoBenderState& s, double u_V, double dt_s) noexcept;

/// The state at rest at `u_V` reached from 0 V long ago (hysteresis from the virgin state, creep
/// settled): the start of a simulation that is not to show the power-up's transient.
PiezoBenderState settled_bender(const PiezoBenderParams& p, double u_V) noexcept;

}  // namespace mc::microworld
