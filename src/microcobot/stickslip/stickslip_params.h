#pragma once
/// @file
/// The aggregate parameters of one stick-slip axis (thesis ch. 2, Table 2.8, and the
/// values the thesis leaves undetermined, chosen in docs/parameters.md).
/// `microcobot stickslip params --json` prints them; `--params FILE.yaml` reads the same keys.

#include <string>

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
  /// PE ringing amplitude (its modes' distance from their static equilibrium) beyond which the
  /// step is sub-stepped: the ringing an edge excites decides the slip (docs/concepts/stick-slip.md).
  double substep_ringing_m = 3e-9;

  template <class V>
  void visit(V& v) {
    v("dt_s", dt_s);
    v("substeps", substeps);
    v("substep_edge_V", substep_edge_V);
    v("substep_strain_fraction", substep_strain_fraction);
    v("substep_ringing_m", substep_ringing_m);
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
  /// Includes validate_step(integrator.dt_s): the contact must be resolvable by the step.
  void validate() const;

  /// Largest omega * h the slider's stick-phase modes may reach: velocity Verlet is stable
  /// below 2; 1.6 keeps a 20 % margin (1.56 at dt_s = 1e-4 measured stable, docs/cli.md).
  static const double kMaxOmegaStep;
  /// Largest gain of the loop PE -> contact -> PE at step `dt_s`: the friction reaction enters
  /// the PE's exact modal step one step late, and the lagged loop of gain
  /// G = (c_a rho0_a + c_b rho0_b) (1/K_pa + 1/K_pb) loses stability the earlier the longer the
  /// step. Measured onsets (docs/cli.md, "Stability limits"): G = 1.5 at 1e-6 s, 0.38 at 1e-5 s,
  /// <= 0.25 at 3e-5 s, fitted by 1.5 (dt / 1e-6 s)^-0.6; the limit is half of it.
  static double max_reaction_loop_gain(double dt_s);
  /// The stick-phase angular frequency of slider part i (0: a, 1: b) [rad/s]: a Gershgorin
  /// bound on its contact mode, sqrt(rho0_i / M_s + 2 k_c / (c_i M_s)).
  double stick_omega_rad_s(int i) const;
  /// Throws InvalidParams naming friction.rho0_a_N_m, rho0_b_N_m or coupling_stiffness_N_m
  /// and the largest value the step `dt_s` allows, when the contact is too stiff for it.
  /// The limit holds for the full step: the stiff phase is the stick (elastic) phase, which
  /// is exactly when the actuator does not sub-step (it sub-steps only near break-away).
  void validate_step(double dt_s) const;

  /// The physically possible states: the PE's displacement within 3 g max|H(U)| (the stroke
  /// the drive can produce, with the ringing's overshoot and the contact's push as margin), the
  /// slider within its end stops plus 1 % of the stroke. Computed once per run (it runs the PI).
  struct PhysicalBounds {
    double x1_m;
    double x2_m;
  };
  PhysicalBounds physical_bounds() const;
  /// Throws ComputationFailed when a simulated state lies outside `bounds` (physical_bounds()).
  /// `where` names the computation in the message.
  void check_physical_bounds(const PhysicalBounds& bounds, double x1_m, double x2_m, double t_s,
                             const std::string& where) const;
};

}  // namespace mc::stickslip
