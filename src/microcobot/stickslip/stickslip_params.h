#pragma once
/// @file
/// The aggregate parameters of one stick-slip axis (thesis ch. 2, Table 2.8 + DESIGN errata 7).
/// `microcobot stickslip params --json` prints them; `--params FILE.yaml` reads the same keys.

#include "microcobot/stickslip/breakaway_table.h"
#include "microcobot/stickslip/drive.h"
#include "microcobot/stickslip/elasto_plastic_friction.h"
#include "microcobot/stickslip/piezo_element.h"
#include "microcobot/stickslip/prandtl_ishlinskii.h"

namespace mc::stickslip {

/// The slider (eq. 2.8) and its guide.
struct SliderParams {
  double mass_kg = 0.0247;          ///< M_s, Table 2.8
  double stroke_m = 0.012;          ///< travel between the end stops (thesis §2.3: 12 mm)
  double initial_position_m = 0.0;  ///< start position; the stops are at -stroke/2 and +stroke/2
  double load_force_N = 0.0;        ///< optional external force on the slider (+ = forward)
  bool attached = true;             ///< false: slider removed (PE alone, thesis §2.5.2.1)

  template <class V>
  void visit(V& v) {
    v("mass_kg", mass_kg);
    v("stroke_m", stroke_m);
    v("initial_position_m", initial_position_m);
    v("load_force_N", load_force_N);
    v("attached", attached);
  }
  void validate() const;
};

/// The fixed-step integrator.
struct IntegratorParams {
  double dt_s = 1e-5;  ///< default step (docs/benchmarks.md: accuracy and speed at this step)
  /// Sub-steps per step while the contact is active (abrupt drive edge, strain beyond
  /// `substep_strain_fraction` z_ba): resolves the slip phases and the PE's 64/120 kHz ringing.
  int substeps = 8;
  double substep_edge_V = 4.0;           ///< drive change per step that counts as an abrupt edge
  double substep_strain_fraction = 0.9;  ///< |z| / z_ba beyond which the contact is sub-stepped

  template <class V>
  void visit(V& v) {
    v("dt_s", dt_s);
    v("substeps", substeps);
    v("substep_edge_V", substep_edge_V);
    v("substep_strain_fraction", substep_strain_fraction);
  }
  void validate() const;
};

struct StickSlipParams {
  PiezoParams pe;
  PiParams hysteresis = default_pi_params();
  FrictionParams friction;
  SliderParams slider;
  BreakawayTable breakaway = default_breakaway_table();
  DriveParams drive;
  IntegratorParams integrator;

  template <class V>
  void visit(V& v) {
    v("pe", pe);
    v("hysteresis", hysteresis);
    v("friction", friction);
    v("slider", slider);
    v("breakaway", breakaway);
    v("drive", drive);
    v("integrator", integrator);
  }
  /// Validates every part; throws mc::InvalidParams naming the field ("pe.mass_kg", ...).
  void validate() const;
};

}  // namespace mc::stickslip
