#include "microcobot/cell/task_io.h"

#include <algorithm>
#include <cmath>

namespace mc::cell {

TaskSensors read_task_sensors(const platform::Platform& p, const Eigen::Vector3d& home_m) noexcept {
  TaskSensors s;
  for (int i = 0; i < 3; ++i) s.tip_m[i] = home_m[i] + p.axis(i).position_m();
  const devices::Vec3 f = p.gripper().contact_force_N();
  s.contact_N = {f.x, f.y, f.z};
  s.grip_N = p.gripper().grip_force_N();
  s.opening_m = p.gripper().opening_m();
  s.gripper_command_m = p.teleop().gripper_opening_m;
  s.yaw_rad = p.yaw_rad();
  return s;
}

AssemblyGoal assembly_goal(const AssemblyJob& job) {
  AssemblyGoal goal;
  goal.part_m = job.nominal_part_m;
  goal.target_m = job.target_m;
  goal.part_height_m = job.world.height_m();
  goal.hole_depth_m = job.world.hole_depth_m;
  goal.clearance_m = job.clearance_m;
  goal.open_m = job.world.gripper.max_opening_m;
  goal.part_yaw_rad = job.nominal_part_yaw_rad;
  goal.target_yaw_rad = job.target_yaw_rad;
  goal.flat_seat = job.flat;
  goal.release = job.release;
  const auto& g = job.world.gripper;
  const double reach = std::hypot(0.5 * g.max_opening_m + g.finger_thickness_m, 0.5 * g.finger_width_m);
  const int n = std::min(job.world.neighbour_count, teleop::FixtureSet::kMaxKeepOuts);
  for (int i = 0; i < n; ++i) {
    const auto& nb = job.world.neighbours[static_cast<std::size_t>(i)];
    auto& k = goal.keep_outs[static_cast<std::size_t>(i)];
    k.xy_m = nb.xy_m;
    k.radius_m = reach + nb.side_m / std::sqrt(2.0) + kKeepOutMargin_m;
    k.top_z_m = nb.top_z_m + kKeepOutClearance_m;
  }
  for (int i = 0; i < job.world.neighbour_count; ++i)
    goal.tallest_neighbour_m =
        std::max(goal.tallest_neighbour_m, job.world.neighbours[static_cast<std::size_t>(i)].top_z_m);
  goal.keep_out_count = n;
  return goal;
}

Eigen::Vector3d stage_home_m(const platform::PlatformConfig& c) {
  return {c.stage.home_x_m, c.stage.home_y_m, c.stage.home_z_m};
}

}  // namespace mc::cell
