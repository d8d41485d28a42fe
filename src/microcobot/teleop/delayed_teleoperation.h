#pragma once
/// @file
/// The coupling system over a delayed, lossy link, 1 DOF, pushed into a stiff contact (the
/// delay sweep: its stability and its settling), by one of three schemes (`Scheme`):
///  - none: position forward, force back, unprotected;
///  - tdpa: the same with time-domain passivity control (passivity.h) at both ports;
///  - mmt:  model-mediated teleoperation: position forward, the slave's estimate of the contact
///          back (contact_estimator.h); the handle feels the master's local model of it
///          (model_mediated_master.h), which the delay cannot destabilise.
///
///   operator's hand --k_h, b_h--> handle (m_m, b_m) --x_m--> link (T_f, jitter, loss) --> slave
///   handle <--f_m-- master PC <--f_e, E_in,s-- link (T_b) <-- contact force f_e of the wall
///
/// Everything is in the master's units (the slave's motion x 1/motion_scale, its forces x
/// force_scale), so that powers compare across the two ports. The slave is a position servo
/// (k_p, b_s) on a mass m_s tracking its desired position, pressing on a wall of stiffness k_e at
/// wall_m: the stiff contact whose delayed force makes the unprotected loop oscillate once
/// k_e T ~ the hand's damping. The network runs at the operator rate (1 kHz); the mechanics at
/// substeps of it.

#include <cstdint>
#include <string>
#include <vector>

#include "microcobot/teleop/contact_estimator.h"
#include "microcobot/teleop/link_emulator.h"

namespace mc::teleop {

enum class Scheme { kNone, kTdpa, kMmt };
/// "none", "tdpa", "mmt".
const char* to_string(Scheme s);
/// Throws InvalidParams naming `name` unless it is one of to_string's names.
Scheme scheme_from_string(const std::string& name);

/// The model-mediated scheme's settings (docs/concepts/teleoperation.md "Settling under long delay").
struct MmtSettings {
  ContactEstimatorParams estimator;
  double time_constant_s = 0.005;       ///< the master's model lag, eq. (1) of model_mediated_master.h
  double prior_stiffness_N_m = 1000.0;  ///< the material's nominal stiffness, before any contact
  /// The geometry's uncertainty on the wall's position: the prior wall is placed this much nearer
  /// than the geometry says, so that the slave's corrections move the model's wall away from the
  /// handle (releasing stored energy) and never towards it (which the passivity controller would
  /// have to absorb by holding the handle deeper: docs/concepts/teleoperation.md).
  double prior_margin_m = 1.5e-3;
  double force_noise_N = 0.0;  ///< std of the slave's force sensor noise
  bool passivity = true;       ///< the model port's passivity controller
};

struct DelayedTeleopParams {
  double rate_Hz = 1000.0;  ///< samples sent each way per second
  int substeps = 10;        ///< mechanics steps per sample
  double handle_mass_kg = 0.1, handle_damping_N_s_m = 0.5;
  double hand_stiffness_N_m = 200.0, hand_damping_N_s_m = 20.0;
  double slave_mass_kg = 0.1, servo_stiffness_N_m = 5000.0, servo_damping_N_s_m = 100.0;
  double wall_m = 0.02;                ///< the contact, 20 mm of hand travel from the start
  double wall_stiffness_N_m = 1000.0;  ///< as the handle feels it (at 1 mm into the wall)
  /// The wall's force law, f = k d (d / 1 mm)^(n - 1) at a depth d: 1 a spring, 1.5 a Hertz
  /// contact. The model-mediated master's model is a spring whatever n (a model mismatch).
  double wall_exponent = 1.0;
  double approach_speed_m_s = 0.02;      ///< the hand's speed towards the wall ...
  double push_depth_m = 0.01;            ///< ... until its target is this far beyond it ...
  double duration_s = 6.0;               ///< ... where it stays until the end
  double max_force_N = 20.0;             ///< the master's actuator saturates here
  double stable_excursion_m = 1e-3;      ///< handle peak-to-peak over the last second, stable below
  double settled_force_tolerance = 0.1;  ///< settled: contact force within this share of its steady value
  double master_damping_N_s_m = 0.0;     ///< a passive damper on the handle (any scheme; TDPA's remedy)
  MmtSettings mmt;
  void validate() const;
  /// The contact force at rest of the undelayed coupling: the hand's spring, the slave's servo and
  /// the wall in series, pressed by the hand's target push_depth_m beyond the wall.
  double steady_contact_force_N() const;
  /// The wall's force at a depth `depth_m` (0 outside). Never allocates.
  double wall_force_N(double depth_m) const noexcept;
};

struct DelayCase {
  double delay_s = 0.0;   ///< round trip (half each way)
  double jitter_s = 0.0;  ///< each way
  double loss = 0.0;      ///< each way
  Scheme scheme = Scheme::kNone;
  std::uint64_t seed = 1;
  double wall_prior_error_m = 0.0;  ///< the microworld geometry's error on the wall's position (mmt)
};

struct DelayCaseResult {
  DelayCase c;
  bool stable = false;
  bool passivity = false;  ///< a passivity controller was on (tdpa; mmt with mmt.passivity)
  /// stable, and the contact force over the last second within settled_force_tolerance of
  /// steady_contact_force_N.
  bool settled = false;
  double settling_time_s = 0.0;  ///< from then on the force is within tolerance and the handle within
                                 ///< half of stable_excursion_m of its final position (inf: never)
  double steady_contact_force_N = 0.0;
  double contact_force_mean_N = 0.0;     ///< over the last second
  double contact_force_max_error = 0.0;  ///< max |f_e - steady| / steady over the last second
  /// min over time of PO_m and PO_s (none, tdpa), of the model port's PO (mmt)
  double min_observed_energy_J = 0.0;
  double max_handle_excursion_m = 0.0;  ///< handle peak-to-peak over the last second
  double rms_tracking_error_m = 0.0;    ///< slave minus master position (master units)
  double max_handle_force_N = 0.0;
  double max_contact_force_N = 0.0;
  double dissipated_J = 0.0;                                         ///< by the passivity controllers
  double final_model_wall_m = 0.0, final_model_stiffness_N_m = 0.0;  ///< mmt: the master's model at the end
  // Time series at the sample rate (for the report).
  std::vector<double> t_s, handle_m, slave_m, handle_force_N, contact_force_N, po_master_J, po_slave_J;
};

/// Runs one case. Throws InvalidParams for bad parameters.
DelayCaseResult run_delay_case(const DelayedTeleopParams& p, const DelayCase& c, bool keep_series = false);

}  // namespace mc::teleop
