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
///
/// Each transform's rotation is a unit quaternion about z (q = [0, 0, sin(a/2), cos(a/2)]).
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

/// What the scene update draws: the bodies' sizes [m].
struct RobotBodies {
  double part_side_m = 0.0;      ///< the part's square side (0: no part drawn)
  double part_height_m = 0.0;    ///< its height
  double finger_width_m = 0.0;   ///< a finger's width along the gripper's x and y
  double finger_length_m = 0.0;  ///< a finger's length, down from the tool point's height
};

/// One transform of the tree: `child`'s origin at (x, y, z) in `parent`, turned by `yaw` about z.
struct FrameTransform {
  std::string_view parent, child;  ///< views of string literals (null-terminated, static)
  double x_m = 0.0, y_m = 0.0, z_m = 0.0, yaw_rad = 0.0;
};
/// The most transforms a sample gives (tool, gripper, two fingers, part).
inline constexpr std::size_t kMaxRobotFrames = 5;
using FrameTransforms = std::array<FrameTransform, kMaxRobotFrames>;

class RobotFrames {
 public:
  /// Reads the channels it needs from `schema`. Throws mc::InvalidParams naming a built-in
  /// channel the schema lacks; the part's channels are optional.
  explicit RobotFrames(const platform::TelemetrySchema& schema);

  /// The transforms of one sample into `out`; returns how many (4, or 5 with the part). Non-finite
  /// values become 0 (a viewer must not get NaN). Allocates nothing.
  std::size_t transforms(const platform::TelemetrySample& s, FrameTransforms& out) const;
  /// foxglove.FrameTransforms of one sample (its loop time stamps every transform), into `out`
  /// (replaced). Non-finite values are sent as 0 (a viewer must not get NaN).
  void transforms_json(const platform::TelemetrySample& s, std::string& out) const;
  /// foxglove.SceneUpdate of `bodies`, stamped `t_s` (loop time).
  std::string scene_update_json(const RobotBodies& bodies, double t_s) const;
  bool has_part() const { return part_.has_value(); }

  /// JSON schemas of the two messages as sent (the fields these messages use, in Foxglove's
  /// names and types), for the channels' advertisements.
  static std::string transforms_schema();
  static std::string scene_update_schema();

 private:
  struct PartChannels {
    std::size_t x, y, z, yaw;
  };
  std::size_t x_, y_, z_, theta_, opening_;
  std::optional<PartChannels> part_;
};

}  // namespace mc::live
