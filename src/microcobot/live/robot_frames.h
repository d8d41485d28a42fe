#pragma once
/// @file
/// The platform as a tree of frames and the bodies drawn in them, for a 3-D viewer (Foxglove's 3D
/// panel live, or any reader of a recording): a `foxglove.FrameTransforms` message from each
/// telemetry sample and a `foxglove.SceneUpdate` of the bodies (docs/console.md, "In 3-D").
///
/// Frames, in metres and radians, z up (the stage's axes):
///
///   world                              the bench: the stage's coordinates
///   world -> tool                      the Cartesian robot's tool point, where its sensors put it
///   tool -> gripper                    turned about z by the rotary axis' measured angle
///   gripper -> finger_left|right       +-opening/2 along the gripper's y (the measured opening)
///   world -> part                      the part's true pose (x, y, z, yaw), with the simulation's
///                                      ground truth channels only
///   world -> positioner                the parallel positioner's platform {P} in its base {H} as
///                                      its legs' sensors measure it (R = Rz(rz) Ry(ry) Rx(rx)),
///                                      with a parallel positioner only; its home frame {H} is the
///                                      world's origin
///   world -> positioner_base           the positioner's base frame {B}: {H} is (0, 0, h + o) in it
///                                      (with the positioner's geometry, as every frame below)
///   positioner_base -> carriage_i      leg i's two-axis carriage: its spherical joint's centre B_i,
///                                      x along the leg's radial axis e_r (turned by phi_i about z)
///   positioner_base -> leg_i           leg i's rigid link: origin at B_i, z along the link to the
///                                      platform's revolute joint P_i, so that (0, 0, L) is P_i
///
/// B_i and P_i are the legs' closure at the measured pose (motion::ParallelKinematics::closures,
/// the inverse kinematics of parallel_kinematics.h; structure: parallel_geometry.h, after the
/// 6-DOF parallel positioner of T. Lu, "Design and Realization of a Desktop Micro-manipulation
/// Cobotic Platform", PhD thesis, Université Pierre et Marie Curie, 2016, §2.3, Fig. 2.4): the
/// legs are drawn where the pose the sensors measure puts them. A pose no leg set closes (a sensor
/// fault) sends the positioner's frame and its base alone, and a viewer keeps the legs where they last were.
///
/// A rotation about z by a is the quaternion [0, 0, sin(a/2), cos(a/2)]; the positioner's is
/// q = qz(rz) qy(ry) qx(rx), the product of its three elementary turns.
/// The scene's bodies are boxes sized from the scene (the part's side and height, the fingers'
/// width) and, with the positioner's geometry, its base plate, carriages, links (cylinders of
/// length L), joints (spheres) and moving platform (a plate under {P}'s origin, the default pivot,
/// marked by a sphere): they move only through the transforms, so the scene is sent again only when the scene
/// changes (a restart, another scene). Built on the drain and status threads, never on the loop.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "microcobot/motion/parallel_kinematics.h"
#include "microcobot/platform/telemetry_schema.h"

namespace mc::live {

/// The topics of the two messages, live and in recordings.
inline constexpr std::string_view kTransformsTopic = "/tf";
inline constexpr std::string_view kRobotSceneTopic = "/robot/scene";

/// What the scene update draws: the bodies' sizes [m].
struct RobotBodies {
  double part_side_m = 0.0;      ///< the part's square side (0: no part drawn)
  double part_height_m = 0.0;    ///< its height
  double finger_width_m = 0.0;   ///< a finger's width along the gripper's x and y
  double finger_length_m = 0.0;  ///< a finger's length, down from the tool point's height
  bool operator==(const RobotBodies&) const = default;
};

/// One transform of the tree: `child`'s origin at (x, y, z) in `parent`, turned by the unit
/// quaternion (qx, qy, qz, qw).
struct FrameTransform {
  std::string_view parent, child;  ///< views of string literals (null-terminated, static)
  double x_m = 0.0, y_m = 0.0, z_m = 0.0;
  double qx = 0.0, qy = 0.0, qz = 0.0, qw = 1.0;
};
/// The most transforms a sample gives (tool, gripper, two fingers, part, positioner, its base,
/// three carriages and three links).
inline constexpr std::size_t kMaxRobotFrames = 6 + 1 + 2 * motion::kParallelLegs;
using FrameTransforms = std::array<FrameTransform, kMaxRobotFrames>;

class RobotFrames {
 public:
  /// Reads the channels it needs from `schema`. Throws mc::InvalidParams naming a built-in
  /// channel the schema lacks (or, from its validation, a field of `positioner`); the part's
  /// channels are optional. `positioner`: the parallel positioner's geometry, whose base, legs and
  /// platform are then drawn when the schema has its pose (null: its frame alone).
  explicit RobotFrames(const platform::TelemetrySchema& schema,
                       const motion::ParallelGeometryParams* positioner = nullptr);
  /// Whether `schema` has the channels the constructor needs (the stage's, the rotary axis' and
  /// the gripper's).
  static bool fits(const platform::TelemetrySchema& schema);

  /// The transforms of one sample into `out`; returns how many (4, then the part and the
  /// positioner where the schema has them, then its base, carriages and links with its
  /// geometry and a pose its legs close at). Non-finite
  /// values become 0 (a viewer must not get NaN). Allocates nothing.
  std::size_t transforms(const platform::TelemetrySample& s, FrameTransforms& out) const;
  /// foxglove.FrameTransforms of one sample (its loop time stamps every transform), into `out`
  /// (replaced). Non-finite values are sent as 0 (a viewer must not get NaN).
  void transforms_json(const platform::TelemetrySample& s, std::string& out) const;
  /// foxglove.SceneUpdate of `bodies`, stamped `t_s` (loop time).
  std::string scene_update_json(const RobotBodies& bodies, double t_s) const;
  bool has_part() const { return part_.has_value(); }
  bool has_positioner() const { return positioner_.has_value(); }
  /// The positioner's kinematics the legs are drawn with (null: no legs drawn).
  const motion::ParallelKinematics* positioner_kinematics() const {
    return kinematics_ ? &*kinematics_ : nullptr;
  }

  /// JSON schemas of the two messages as sent (the fields these messages use, in Foxglove's
  /// names and types), for the channels' advertisements.
  static std::string transforms_schema();
  static std::string scene_update_schema();

 private:
  struct PartChannels {
    std::size_t x, y, z, yaw;
  };
  struct PositionerChannels {
    std::size_t x, y, z, rx, ry, rz;
  };
  std::size_t x_, y_, z_, theta_, opening_;
  std::optional<PartChannels> part_;
  std::optional<PositionerChannels> positioner_;
  std::optional<motion::ParallelKinematics> kinematics_;  // with the positioner's pose and geometry
  double leg_heading_rad_[motion::kParallelLegs] = {};    // phi_i: each carriage's e_r about z

  /// The base, carriages and links at the sample's pose, from out[n]; returns the new count.
  std::size_t positioner_frames(const platform::TelemetrySample& s, FrameTransforms& out,
                                std::size_t n) const;
};

}  // namespace mc::live
