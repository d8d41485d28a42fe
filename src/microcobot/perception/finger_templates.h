#pragma once
/// @file
/// Where the live vision takes a finger tip's template (the vision positioner, the grip gauge):
/// the finger's outer half with 12 um of background beside it, from 5 um beyond the finger's end
/// 42 um up the finger. The jaw side, where a gripped part touches, is left out, so a part
/// between the fingers never enters a tip's template (a template over a part's edge or its
/// defocused glow holds something that does not move with the tip). The end's edge is in: it
/// fixes the rows (with it the live click-to-go rests within 0.05 um in y: docs/benchmarks.md).
/// The finger: a bar along +y from its end at the tool point's
/// y - width / 2, its inner face at the tool point's x -+ opening / 2 (platform/camera_scene.cc).

#include <Eigen/Core>

#include "microcobot/imaging/pixel_roi.h"
#include "microcobot/vision/affine_calibration.h"

namespace mc::perception {

/// The template of the left (`side` -1) or right (+1) finger's tip, in the image, with the tool
/// point at `tool_px`, the fingers `opening_m` apart and `finger_width_m` wide: the box around the
/// region's corners mapped through `map` (pixel = A stage + b). `inner`: the finger's inner half
/// and 12 um of the jaw instead (for a finger whose outer side is out of the image; a part held
/// between the fingers then enters the template). `yaw_rad`: the fingers turned by the rotary axis
/// about the tool point (the region turned with them; the box around its turned corners).
imaging::PixelRoi finger_tip_template(const vision::AffineMap& map, const Eigen::Vector2d& tool_px, int side,
                                      double opening_m, double finger_width_m, bool inner = false,
                                      double yaw_rad = 0.0);

}  // namespace mc::perception
