#pragma once
/// @file
/// The evaluation of the five actuator-system options of the TéléTweez (thesis section 4.4.1,
/// Table 4.7), computed from the specifications of Table 4.3 and each option's own figures:
/// the ERF field threshold, the piezo amplifier (eq. A.8), the piezo brake (eq. 4.2-4.3), the
/// ball screw and transmission (eq. B.6, 4.4, 4.5).

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "microcobot/tweezers/specs.h"

namespace mc::tweezers {

/// The figures the thesis gives for each option (defaults are the thesis's values; the ERF gap
/// is a documented choice, see docs/parameters.md).
struct OptionFigures {
  // Option 1, ERF piston: no significant effect below 1 kV/mm [Yongliang 2010].
  double erf_threshold_field_V_per_m = 1e6;
  double erf_gap_m = 0.5e-3;  ///< documented choice: piston gap (not given in the thesis)
  // Option 2, MRF piston: the coils ran within the allowed supply (section 4.4.1.2).
  double mrf_voltage_V = 100.0;
  // Option 3.1, piezo piston with amplifier: best candidate of Table 4.5 (PI P-010.80P).
  double amp_length_m = 111e-3, amp_stroke_m = 120e-6, amp_e_m = 5e-3, amp_a_m = 7e-3;
  double piezo_voltage_V = 100.0;  ///< PI stacks need up to 100 V
  // Option 3.2, piezo brake (PI P-830.20).
  double brake_max_force_N = 1000.0, brake_travel_used = 0.85, brake_mu = 0.1, brake_geometry = 0.5;
  // Option 4, DC motor + ball screw.
  double motor_voltage_V = 4.5, motor_torque_Nm = 2.2e-3;
  double screw_diameter_m = 4e-3, screw_lead_m = 1e-3, screw_mu = 0.01;
  double alpha_rad = 63.0 * 3.14159265358979323846 / 180.0, eta_t = 0.9;  ///< eta_t: documented choice
};

/// One row of Table 4.7.
struct OptionEvaluation {
  std::string name;
  double supply_voltage_V = 0;    ///< voltage the option needs
  std::optional<double> force_N;  ///< computed force at the fingers, when the thesis gives figures
  std::string force_source;       ///< how force_N was obtained, or the thesis's reported outcome
  bool meets_supply = false;      ///< supply_voltage_V <= specs.max_voltage_V
  bool meets_force = false;       ///< force >= eq. 4.1 (computed, or the reported experiment)
  bool active = false;            ///< can render active force (not only resistance)
  std::string difficulty;         ///< realization difficulty as the thesis assesses it
  bool selected = false;
};

/// Evaluates the five options against `specs` and selects the one that meets supply and force,
/// preferring active rendering, then low difficulty (the thesis picks option 4).
std::vector<OptionEvaluation> evaluate_actuator_options(const TweezersSpecs& specs = {},
                                                        const OptionFigures& figures = {});

nlohmann::json to_json(const OptionEvaluation& e);

}  // namespace mc::tweezers
