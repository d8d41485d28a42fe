#pragma once
/// @file
/// What an AssemblyTask reads and is told, taken from a platform and a job: shared by the
/// headless cycle (cell_run.h) and the live console (live/live_task.h), so that both run the
/// same task on the same sensors.

#include <Eigen/Dense>

#include "microcobot/cell/assembly_batch.h"
#include "microcobot/cell/assembly_task.h"
#include "microcobot/platform/platform.h"

namespace mc::cell {

/// The slave's sensors now, world frame (`home_m`: the stage's home, platform.stage.home_*).
/// Real-time safe: reads only.
TaskSensors read_task_sensors(const platform::Platform& p, const Eigen::Vector3d& home_m) noexcept;

/// What the cell is told about `job` (its slot's nominal position, the bore, the geometry), and the
/// keep-out regions round its scene's other parts: a cylinder of the open fingers' reach (half the
/// widest opening plus their thickness, to their corner) plus the part's half-diagonal plus
/// kKeepOutMargin_m, up to kKeepOutClearance_m above its top.
AssemblyGoal assembly_goal(const AssemblyJob& job);
constexpr double kKeepOutMargin_m = 10e-6;
constexpr double kKeepOutClearance_m = 20e-6;

/// The stage's home in the world frame.
Eigen::Vector3d stage_home_m(const platform::PlatformConfig& c);

}  // namespace mc::cell
