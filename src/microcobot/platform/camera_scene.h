#pragma once
/// @file
/// What the microscope camera sees of the platform's scene: the configuration's
/// microworld (the pick-and-place part, the pin-in-hole's pin and hole, the optical trap's
/// beads) and the slave's gripper, as the vision module's SceneSnapshot. The camera thread fills
/// one snapshot from each telemetry sample it receives (the tool and part channels, or the
/// probe bead's in the optical-trap scene); velocities (motion blur) come from two samples.

#include <string>

#include "microcobot/imaging/scene_snapshot.h"
#include "microcobot/platform/platform.h"
#include "microcobot/platform/platform_config.h"

namespace mc::platform {

/// Sets `config`'s scene by name: "pick-place" (the default world, left as it is), "pin-in-hole",
/// "optical-trap", or a YAML file of the microworld's keys over `config.world` (as `serve
/// --scene`). Throws InvalidInput naming `scene`.
void use_scene(PlatformConfig& config, const std::string& scene);
/// The default configuration with the scene `scene` (use_scene).
PlatformConfig scene_config(const std::string& scene);

/// What the renderer needs to form `camera`'s image through its objective `objective` (clamped to
/// the turret).
imaging::CameraParams renderer_params(const devices::CameraDeviceParams& camera, int objective);

/// Where the moving things are (world frame, the telemetry's ground-truth channels).
struct CameraScenePose {
  double tool_x_m = 0.0, tool_y_m = 0.0, tool_z_m = 0.0;  ///< finger tips' centre (slave_*_m)
  double opening_m = 0.0;                                 ///< gripper opening
  double tool_yaw_rad = 0.0;                              ///< the fingers' yaw (slave_theta_rad)
  /// The fingers' common-mode bend (a lateral contact force): their tips drawn this far from the
  /// tool point (the telemetry has no channel for it: 0 from pose_from_telemetry).
  double deflection_x_m = 0.0, deflection_y_m = 0.0;
  double part_x_m = 0.0, part_y_m = 0.0, part_z_m = 0.0;  ///< part centre, or the probe bead's
  double part_yaw_rad = 0.0;                              ///< the part's orientation
  double vx_m_s = 0.0, vy_m_s = 0.0;                      ///< the tool's velocity
  double part_vx_m_s = 0.0, part_vy_m_s = 0.0;
  /// The substrate carried by the parallel positioner: its displacement and heading from home
  /// (devices::SceneSnapshot::seat_m); the hole and the other parts drawn where it takes them.
  double seat_x_m = 0.0, seat_y_m = 0.0, seat_yaw_rad = 0.0;
};

/// The pose at the scene's start: the tool at the stage's home, the gripper open, the part at
/// its start (the probe bead in the trap at the home).
CameraScenePose initial_pose(const PlatformConfig& config);
/// The pose in a telemetry sample (velocities from `previous`, taken `dt_s` before; zero
/// without it).
CameraScenePose pose_from_telemetry(const TelemetrySample& now, const TelemetrySample* previous, double dt_s);

/// Fills `snapshot` (object lists cleared, their capacity kept) with the scene of `config` at
/// `pose`; the fingers as wide as `world.gripper.finger_width_m`.
void fill_camera_scene(const PlatformConfig& config, const CameraScenePose& pose,
                       imaging::SceneSnapshot& snapshot);

}  // namespace mc::platform
