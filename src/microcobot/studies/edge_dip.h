#pragma once
/// @file
/// What one abrupt edge does to a stuck slider: the backward dip while the PE falls, measured on
/// the actuator model (thesis §2.4, eq. 2.1-2.21), against the edge's voltage drop ΔV, its slew
/// and the operating point. It decides between two mechanisms of the tracking error's peaks
/// (docs/concepts/control.md, "Edge transient"):
///
///  - friction drag during the slip: once the contact has broken away, the kinetic friction
///    F_k ~ rho0 z_ss pulls the slider back for as long as the PE keeps falling, so the dip grows
///    with the edge's duration T = ΔV / S, as (F_k / M_s) T^2 / 2 if the slider starts from rest:
///    roughly ΔV^2 at a fixed slew;
///  - elastic pre-sliding: the contact's strain reverses from +z to -z before it slips; the slider
///    moves with it by about z_ba (F_s / sigma_0), independent of ΔV once the edge is long enough
///    to break the contact away;
///  - recoil: the slip leaves the contact strained, and once the PE stops the strain springs the
///    slider back on the contact's modes (600 Hz and 1.64 kHz, Table 2.8) by a fixed share of the
///    PE's stroke g ΔV, after the edge rather than during it: the dip grows as ΔV and hardly with
///    the edge's duration.
///
/// Each case ramps the PE up at the operating point's speed (the slider sticks and follows), then
/// falls by ΔV at the slew S from the top voltage, then either holds or turns back by `unload_V`
/// at the same slew (the tracking controller's unloading), and holds. The dip is the slider's
/// largest excursion behind its position at the edge's start; the net backslip is where it comes
/// to rest (the mean over the window's last millisecond) against that start.

#include <string>
#include <vector>

#include "microcobot/stickslip/actuator.h"

namespace mc::studies {

/// One edge of the study.
struct EdgeCase {
  double top_V = 100.0;      ///< the voltage the edge starts from [V]
  double drop_V = 68.38;     ///< ΔV: how far it falls [V]
  double slew_V_s = 1.0e6;   ///< S: the fall's rate [V/s] (the amplifier's: 1 V/us)
  double ramp_m_s = 100e-6;  ///< the ramp's speed before the edge (the slider's speed) [m/s]
  double unload_V = 0.0;     ///< after the fall, turn back up by this much at S (0: hold) [V]
  double window_s = 10e-3;   ///< how long the slider is watched after the edge starts [s]
  /// A shaped edge: the edge and its unloading in two halves (ΔV / 2, then unload_V / 2), the
  /// second starting this long after the first (at least one half's duration); the halves'
  /// recoils cancel on a contact mode whose half period this is (a zero-vibration shaper, Singer
  /// & Seering 1990). 0: one edge [s].
  double split_delay_s = 0.0;
};

/// What one edge did.
struct EdgeDip {
  EdgeCase edge;
  double edge_s = 0.0;    ///< T = ΔV / S [s]
  double dip_m = 0.0;     ///< largest excursion behind the start (>= 0) [m]
  double dip_at_s = 0.0;  ///< when it was reached, from the edge's start [s]
  double net_m = 0.0;     ///< where the slider rests against the start (< 0: behind) [m]
  /// How far the dip overshoots where the slider comes to rest: dip + net, the part a lead on the
  /// predicted backslip cannot split [m].
  double overshoot_m = 0.0;
  double z_ba_m = 0.0;       ///< the contact's break-away strain at this operating point [m]
  double pe_travel_m = 0.0;  ///< the PE's static stroke over ΔV: g ΔV [m]
};

/// Runs one edge on `model` from its initial state (operating point: a sawtooth of amplitude
/// ΔV at the ramp's frequency, forward). Throws mc::InvalidInput naming a bad field of `edge`,
/// mc::ComputationFailed if the model diverges.
EdgeDip run_edge(const stickslip::ActuatorModel& model, const EdgeCase& edge);

/// The exponent p and factor c of y = c x^p fitted by least squares in log-log over the points
/// with x > 0 and y > 0 (at least two; else NaN).
struct PowerFit {
  double exponent = 0.0, factor = 0.0;
  int points = 0;
};
PowerFit fit_power(const std::vector<double>& x, const std::vector<double>& y);

/// The study: ΔV swept at the amplifier's slew, the slew swept at the tracking controller's ΔV,
/// the ramp's speed and the top voltage swept at both, each with and without unloading.
struct EdgeStudy {
  std::vector<EdgeDip> drop_sweep, slew_sweep, speed_sweep, top_sweep;
  std::vector<EdgeDip> drop_sweep_unloaded, slew_sweep_unloaded;
  /// The tracking controller's edge (unloaded) split in two halves, against the halves' delay
  /// (60 us to 1.26 ms), and the delay whose dip is least.
  std::vector<EdgeDip> split_sweep;
  EdgeDip least_split;
  PowerFit dip_vs_drop, dip_vs_duration;  ///< held edges: dip ~ ΔV^p, dip ~ T^p (ΔV fixed)
  PowerFit dip_vs_drop_unloaded, dip_vs_duration_unloaded;
  double z_ba_m = 0.0;  ///< at the tracking controller's edge (68.38 V, 100 um/s)
  /// From the held edges' fits, dip ~ ΔV^p and ~ T^q: "drag" (p >= 1.5, q > 0.5), "pre-sliding"
  /// (|p| < 0.3), "recoil" (0.7 <= p <= 1.3, |q| < 0.3), else "mixed".
  std::string mechanism;
};

/// Runs every case of the study on `model`; `progress` (may be empty) is told each case done.
EdgeStudy run_edge_study(const stickslip::ActuatorModel& model,
                         const std::function<void(std::size_t done, std::size_t total)>& progress = {});

}  // namespace mc::studies
