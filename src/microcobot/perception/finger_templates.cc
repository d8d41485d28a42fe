#include "microcobot/perception/finger_templates.h"

#include <cmath>

namespace mc::perception {

imaging::PixelRoi finger_tip_template(const vision::AffineMap& map, const Eigen::Vector2d& tool_px, int side,
                                      double opening_m, double finger_width_m, bool inner, double yaw_rad) {
  constexpr double kBeyond = 12e-6;  // background beside the finger's outer edge [m]
  constexpr double kBelow = 5e-6;    // the template starts this far beyond the finger's end [m]
  constexpr double kAlong = 42e-6;   // and spans this much [m]
  const double w = finger_width_m;
  // In stage coordinates from the tool point: x from the finger's centre line outward past its
  // outer edge (inward past its inner face), y from just beyond the finger's end up the finger
  // (the end's edge fixes the rows).
  const double x0 = side * 0.5 * (opening_m + w);
  const double x1 = inner ? side * (0.5 * opening_m - kBeyond) : side * (0.5 * opening_m + w + kBeyond);
  const double y0 = -0.5 * w - kBelow, y1 = y0 + kAlong;
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (double x : {x0, x1})
    for (double y : {y0, y1}) {
      const Eigen::Vector2d corner = tool_px + map.pixel_step(Eigen::Vector2d(c * x - s * y, s * x + c * y));
      lo = lo.cwiseMin(corner);
      hi = hi.cwiseMax(corner);
    }
  return {static_cast<int>(std::lround(lo.x())), static_cast<int>(std::lround(lo.y())),
          static_cast<int>(std::lround(hi.x() - lo.x())), static_cast<int>(std::lround(hi.y() - lo.y()))};
}

}  // namespace mc::perception
