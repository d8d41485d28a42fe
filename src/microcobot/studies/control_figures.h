#pragma once
/// @file
/// The figures of stick-slip motion control (thesis section 2.7): velocity control, hybrid
/// positioning and trajectory tracking, each beside its baselines on the same model and sensor,
/// and the full report's part on the default parameters. Each experiment adds its section's
/// results and figures to a report, fills an optional table of the main run, and returns its
/// summary (the `control` commands' JSON).

#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "microcobot/core/csv.h"
#include "microcobot/motion/control_params.h"
#include "microcobot/motion/step_map.h"
#include "microcobot/motion/xyz_stage.h"
#include "microcobot/report/report.h"
#include "microcobot/stickslip/actuator.h"

namespace mc::studies {

/// The axis' model and its step map (about a second to build), shared by the experiments.
struct ControlPlant {
  stickslip::ActuatorModel model;
  motion::StepMap map;
  explicit ControlPlant(const motion::ControlParams& p) : model(p.model), map(model, p.step_map) {}
};

/// A trajectory to track (`control trajectory`'s flags): a 1-D profile (trapezoid, sine, stream)
/// or a 3-D path (line, arc).
struct TrajectoryCase {
  std::string profile = "trapezoid";
  std::string direction = "forward";  ///< forward | backward (1-D profiles)
  double distance = 100e-6;           ///< trapezoid, line [m]
  double velocity = 0.0;              ///< [m/s]; 0: limits.max_velocity_m_s
  double acceleration = 0.0;          ///< [m/s^2]; 0: limits.max_acceleration_m_s2
  double jerk = 0.0;                  ///< [m/s^3]; 0: path.max_jerk_m_s3
  double amplitude = 20e-6;           ///< sine [m]
  double frequency = 1.0;             ///< sine [Hz]
  double radius = 100e-6;             ///< arc [m]
  double angle = M_PI;                ///< arc [rad]
};

/// Velocity control at `speed` in direction `dir` for `duration` s (Fig. 2.18-2.19): the
/// model-based PID, the thesis's PID and open-loop step counting.
nlohmann::json velocity_experiment(const motion::ControlParams& p, const ControlPlant& plant, double speed,
                                   stickslip::Direction dir, double duration, report::Report& r,
                                   CsvTable* table);
/// A hybrid move of `axis` from `start` to `target` beside the open-loop and thesis-PID baselines.
nlohmann::json position_experiment(const motion::ControlParams& p, const ControlPlant& plant,
                                   motion::Axis axis, double start, double target, report::Report& r,
                                   CsvTable* table);
/// The tracking controller on trajectory `o` beside the hybrid controller and the thesis's PID.
/// Throws InvalidParams (limits) or naming the flags of a trajectory over the work budget.
nlohmann::json trajectory_experiment(const motion::ControlParams& p0, const ControlPlant& plant,
                                     const TrajectoryCase& o, report::Report& r, CsvTable* table);

/// The control part of the full report: both velocity directions, two moves, four trajectories.
void control_figures(report::Report& r);

}  // namespace mc::studies
