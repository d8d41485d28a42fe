#include "microcobot/platform/camera_scene.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string_view>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "microcobot/core/params.h"

namespace mc::platform {

namespace {

// A built-in channel (0 where the platform does not record it: the samples are zero-filled).
double channel(const TelemetrySample& s, std::string_view name) { return s[telemetry_channel_index(name)]; }

}  // namespace

void use_scene(PlatformConfig& c, const std::string& scene) {
  if (scene == "pin-in-hole") {
    c.world = microworld::pin_in_hole_scene();
  } else if (scene == "optical-trap") {
    use_optical_trap_scene(c);
  } else if (scene != "pick-place") {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(scene, ec))
      throw InvalidInput("--scene '" + excerpt(scene) +
                         "': neither a built-in scene (pick-place, pin-in-hole, optical-trap) nor a "
                         "scene file (a YAML file of the microworld's keys, e.g. scenes/pin-in-hole.yaml)");
    c.world = load_params<microworld::PickPlaceParams>(scene, c.world);
  }
}

PlatformConfig scene_config(const std::string& scene) {
  PlatformConfig c;
  use_scene(c, scene);
  return c;
}

imaging::CameraParams renderer_params(const devices::CameraDeviceParams& camera, int objective) {
  const int last = static_cast<int>(camera.objectives.size()) - 1;
  imaging::CameraParams cp;
  cp.sensor = camera.sensor;
  cp.objective = camera.objectives.at(static_cast<std::size_t>(std::clamp(objective, 0, last)));
  cp.illumination = camera.illumination;
  cp.view_center_x_m = camera.view_center_x_m;
  cp.view_center_y_m = camera.view_center_y_m;
  return cp;
}

CameraScenePose initial_pose(const PlatformConfig& c) {
  CameraScenePose p;
  p.tool_x_m = c.stage.home_x_m;
  p.tool_y_m = c.stage.home_y_m;
  p.tool_z_m = c.stage.home_z_m;
  if (c.optical_trap_scene()) {
    p.part_x_m = c.stage.home_x_m;
    p.part_y_m = c.stage.home_y_m;
    p.part_z_m = c.optical_trap.trap.bead_radius_m;  // the probe bead just above the dish
  } else {
    p.opening_m = c.world.gripper.max_opening_m;
    p.part_x_m = c.world.part_start_m.x();
    p.part_y_m = c.world.part_start_m.y();
    p.part_z_m = 0.5 * c.world.height_m();
    p.part_yaw_rad = c.world.part_yaw_rad;
  }
  return p;
}

CameraScenePose pose_from_telemetry(const TelemetrySample& now, const TelemetrySample* previous,
                                    double dt_s) {
  CameraScenePose p;
  p.tool_x_m = channel(now, "slave_x_m");
  p.tool_y_m = channel(now, "slave_y_m");
  p.tool_z_m = channel(now, "slave_z_m");
  p.opening_m = channel(now, "gripper_opening_m");
  p.tool_yaw_rad = channel(now, "slave_theta_rad");
  p.part_x_m = channel(now, "part_x_m");
  p.part_y_m = channel(now, "part_y_m");
  p.part_z_m = channel(now, "part_z_m");
  p.part_yaw_rad = channel(now, "part_yaw_rad");
  if (previous && dt_s > 0.0) {
    p.vx_m_s = (p.tool_x_m - channel(*previous, "slave_x_m")) / dt_s;
    p.vy_m_s = (p.tool_y_m - channel(*previous, "slave_y_m")) / dt_s;
    p.part_vx_m_s = (p.part_x_m - channel(*previous, "part_x_m")) / dt_s;
    p.part_vy_m_s = (p.part_y_m - channel(*previous, "part_y_m")) / dt_s;
  }
  return p;
}

void fill_camera_scene(const PlatformConfig& c, const CameraScenePose& pose, imaging::SceneSnapshot& s) {
  s.clear_objects();
  if (c.optical_trap_scene()) {
    // A Petri dish seen in transmitted or reflected light: a glass bottom, faint texture.
    const auto& trap = c.optical_trap.trap;
    s.substrate.reflectance = 0.35;
    s.substrate.texture_contrast = 0.03;
    s.substrate.texture_grain_m = 0.5e-6;
    imaging::Bead probe;
    probe.x_m = pose.part_x_m, probe.y_m = pose.part_y_m, probe.z_m = pose.part_z_m;
    probe.radius_m = trap.bead_radius_m;
    probe.vx_m_s = pose.part_vx_m_s, probe.vy_m_s = pose.part_vy_m_s;
    s.beads.push_back(probe);
    const Eigen::Vector2d o = c.optical_trap.obstacle_m({c.stage.home_x_m, c.stage.home_y_m});
    imaging::Bead stuck;
    stuck.x_m = o.x(), stuck.y_m = o.y(), stuck.z_m = trap.obstacle_radius_m;
    stuck.radius_m = trap.obstacle_radius_m;
    s.beads.push_back(stuck);
    return;
  }
  // Pick-and-place (and pin-in-hole): a lapped steel substrate, the brass part, the hole at the
  // target, the two fingers closing along x.
  const auto& w = c.world;
  // What rides on the carried seat: turned about the world's origin (the top plate's centre at
  // home), then moved with it.
  const double cy = std::cos(pose.seat_yaw_rad), sy = std::sin(pose.seat_yaw_rad);
  const auto carried = [&](const Eigen::Vector2d& p) {
    return Eigen::Vector2d(pose.seat_x_m + cy * p.x() - sy * p.y(), pose.seat_y_m + sy * p.x() + cy * p.y());
  };
  if (w.hole_side_m > 0.0) {
    imaging::Hole h;
    const Eigen::Vector2d at = carried(w.target_m.head<2>());
    h.x_m = at.x(), h.y_m = at.y();
    h.size_x_m = h.size_y_m = w.hole_side_m;
    h.depth_m = w.hole_depth_m;
    h.angle_rad = w.hole_yaw_rad + pose.seat_yaw_rad;
    s.holes.push_back(h);
  }
  imaging::Part part;
  part.x_m = pose.part_x_m, part.y_m = pose.part_y_m;
  part.z_top_m = pose.part_z_m + 0.5 * w.height_m();
  part.size_x_m = part.size_y_m = w.part_side_m;
  part.vx_m_s = pose.part_vx_m_s, part.vy_m_s = pose.part_vy_m_s;
  part.angle_rad = pose.part_yaw_rad;
  s.parts.push_back(part);  // first: the part the scene is about
  // The other parts of the scene (a grid load's: microworld/neighbours.h), where they stand.
  for (int i = 0; i < w.neighbour_count; ++i) {
    const microworld::NeighbourPart& n = w.neighbours[static_cast<std::size_t>(i)];
    imaging::Part other;
    const Eigen::Vector2d at = carried(n.xy_m);
    other.x_m = at.x(), other.y_m = at.y();
    other.z_top_m = n.top_z_m;
    other.size_x_m = other.size_y_m = n.side_m;
    other.angle_rad = n.yaw_rad + pose.seat_yaw_rad;
    s.parts.push_back(other);
  }
  const double finger_width_m = w.gripper.finger_width_m;
  // A lateral force bends both benders: their tips move by the deflection, drawn as the bars
  // shifted (a 2 mm bender bent by a few um: its end turns by 3 d / 2 L, under 0.01 rad).
  const double tip_x = pose.tool_x_m + pose.deflection_x_m, tip_y = pose.tool_y_m + pose.deflection_y_m;
  for (int side : {-1, 1}) {
    imaging::Finger f;
    f.width_m = finger_width_m;
    f.tip_x_m = tip_x + side * 0.5 * (std::max(pose.opening_m, 0.0) + finger_width_m);
    f.tip_y_m = tip_y - 0.5 * finger_width_m;  // the end of the bar covers the tool point
    f.z_tip_m = pose.tool_z_m;
    f.length_m = w.gripper.finger_length_m;
    f.rise = 0.5;  // the benders come down to the part at about 27 degrees from the substrate
    f.vx_m_s = pose.vx_m_s, f.vy_m_s = pose.vy_m_s;
    f.angle_rad = pose.tool_yaw_rad;  // turned about the tool point by the rotary axis
    f.pivot_x_m = tip_x, f.pivot_y_m = tip_y;
    s.fingers.push_back(f);
  }
}

}  // namespace mc::platform
