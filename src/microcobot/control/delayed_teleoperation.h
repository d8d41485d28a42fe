#pragma once
/// @file
/// The coupling system over a delayed, lossy link, 1 DOF, pushed into a stiff contact (issue
/// #17's delay sweep): position forward, force back, with or without time-domain passivity
/// control (passivity.h) at both ports.
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
#include <vector>

#include "microcobot/control/link_emulator.h"

namespace mc::control {

struct DelayedTeleopParams {
  double rate_Hz = 1000.0;  ///< samples sent each way per second
  int substeps = 10;        ///< mechanics steps per sample
  double handle_mass_kg = 0.1, handle_damping_N_s_m = 0.5;
  double hand_stiffness_N_m = 200.0, hand_damping_N_s_m = 20.0;
  double slave_mass_kg = 0.1, servo_stiffness_N_m = 5000.0, servo_damping_N_s_m = 100.0;
  double wall_m = 0.02;                ///< the contact, 20 mm of hand travel from the start
  double wall_stiffness_N_m = 1000.0;  ///< as the handle feels it
  double approach_speed_m_s = 0.02;    ///< the hand's speed towards the wall ...
  double push_depth_m = 0.01;          ///< ... until its target is this far beyond it ...
  double duration_s = 6.0;             ///< ... where it stays until the end
  double max_force_N = 20.0;           ///< the master's actuator saturates here
  double stable_excursion_m = 1e-3;    ///< handle peak-to-peak over the last second, stable below
  void validate() const;
};

struct DelayCase {
  double delay_s = 0.0;   ///< round trip (half each way)
  double jitter_s = 0.0;  ///< each way
  double loss = 0.0;      ///< each way
  bool passivity = false;
  std::uint64_t seed = 1;
};

struct DelayCaseResult {
  DelayCase c;
  bool stable = false;
  double min_observed_energy_J = 0.0;   ///< min over time of PO_m and PO_s
  double max_handle_excursion_m = 0.0;  ///< handle peak-to-peak over the last second
  double rms_tracking_error_m = 0.0;    ///< slave minus master position (master units)
  double max_handle_force_N = 0.0;
  double max_contact_force_N = 0.0;
  double dissipated_J = 0.0;  ///< by the passivity controllers
  // Time series at the sample rate (for the report).
  std::vector<double> t_s, handle_m, slave_m, handle_force_N, contact_force_N, po_master_J, po_slave_J;
};

/// Runs one case. Throws InvalidParams for bad parameters.
DelayCaseResult run_delay_case(const DelayedTeleopParams& p, const DelayCase& c, bool keep_series = false);

}  // namespace mc::control
