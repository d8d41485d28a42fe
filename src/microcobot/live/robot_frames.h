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
///                                      with a parallel positioner only; its base is the world's
///                                      origin
///
/// A rotation about z by a is the quaternion [0, 0, sin(a/2), cos(a/2)]; the positioner's is
/// q = qz(rz) qy(ry) qx(rx), the product of its three elementary turns.
/// The scene's bodies are boxes sized from the scene (the part's side and height, the fingers'
/// width): they move only through the transforms, so the scene is sent again only when the scene
/// changes (a restart, another scene). Built on the drain and status threads, never on the loop.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

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
/// The most transforms a sample gives (tool, gripper, two fingers, part, positioner).
inline constexpr std::size_t kMaxRobotFrames = 6;
using FrameTransforms = std::array<FrameTransform, kMaxRobotFrames>;

class RobotFrames {
 public:
  /// Reads the channels it needs from `schema`. Throws mc::InvalidParams naming a built-in
  /// channel the schema lacks; the part's channels are optional.
  explicit RobotFrames(const platform::TelemetrySchema& schema);
  /// Whether `schema` has the channels the constructor needs (the stage's, the rotary axis' and
  /// the gripper's).
  static bool fits(const platform::TelemetrySchema& schema);

  /// The transforms of one sample into `out`; returns how many (4, then the part and the
  /// positioner where the schema has them). Non-finite
  /// values become 0 (a viewer must not get NaN). Allocates nothing.
  std::size_t transforms(const platform::TelemetrySample& s, FrameTransforms& out) const;
  /// foxglove.FrameTransforms of one sample (its loop time stamps every transform), into `out`
  /// (replaced). Non-finite values are sent as 0 (a viewer must not get NaN).
  void transforms_json(const platform::TelemetrySample& s, std::string& out) const;
  /// foxglove.SceneUpdate of `bodies`, stamped `t_s` (loop time).
  std::string scene_update_json(const RobotBodies& bodies, double t_s) const;
  bool has_part() const { return part_.has_value(); }
  bool has_positioner() const { return positioner_.has_value(); }

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
};

}  // namespace mc::live
