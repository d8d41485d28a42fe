#pragma once
/// @file
/// Exact pixel coverage of a rotated rectangle (a part seen at an angle): the area of
/// its intersection with a unit cell, by clipping the rectangle's polygon to the cell
/// (Sutherland-Hodgman) and the shoelace formula. Pure functions, no allocation.

namespace mc::imaging {

/// A rectangle of half sides (a, b) about (u, v) whose first side lies along (cos_t, sin_t), in
/// the coordinates of the cells (any handedness).
struct RotatedRect {
  double u = 0.0, v = 0.0;
  double a = 0.0, b = 0.0;
  double cos_t = 1.0, sin_t = 0.0;
  /// Half extents of its axis-aligned bounding box.
  double half_width() const;
  double half_height() const;
};

/// Area of the rectangle inside the cell [x0, x0 + 1] x [y0, y0 + 1], in [0, 1].
double cell_coverage(const RotatedRect& r, double x0, double y0) noexcept;

}  // namespace mc::imaging
