#include "microcobot/imaging/polygon_coverage.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace mc::imaging {

namespace {

struct Point {
  double x, y;
};

// At most 8 vertices: a convex 4-gon clipped by 4 half-planes gains at most one vertex per cut.
struct Polygon {
  std::array<Point, 12> p;
  int n = 0;
};

// Keeps the part of `in` where `inside(pt) >= 0` (a linear function: the crossing is exact).
template <class F>
void clip(const Polygon& in, Polygon& out, F inside) {
  out.n = 0;
  for (int i = 0; i < in.n; ++i) {
    const Point& a = in.p[static_cast<std::size_t>(i)];
    const Point& b = in.p[static_cast<std::size_t>((i + 1) % in.n)];
    const double fa = inside(a), fb = inside(b);
    if (fa >= 0.0) out.p[static_cast<std::size_t>(out.n++)] = a;
    if ((fa >= 0.0) != (fb >= 0.0)) {
      const double t = fa / (fa - fb);
      out.p[static_cast<std::size_t>(out.n++)] = {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)};
    }
  }
}

}  // namespace

double RotatedRect::half_width() const { return std::abs(cos_t) * a + std::abs(sin_t) * b; }
double RotatedRect::half_height() const { return std::abs(sin_t) * a + std::abs(cos_t) * b; }

double cell_coverage(const RotatedRect& r, double x0, double y0) noexcept {
  // The cell's centre in the rectangle's frame: quick answers far inside and far outside.
  const double dx = x0 + 0.5 - r.u, dy = y0 + 0.5 - r.v;
  const double s = r.cos_t * dx + r.sin_t * dy, t = -r.sin_t * dx + r.cos_t * dy;
  constexpr double kHalfDiagonal = 0.7071067811865476;
  if (std::abs(s) > r.a + kHalfDiagonal || std::abs(t) > r.b + kHalfDiagonal) return 0.0;
  if (std::abs(s) < r.a - kHalfDiagonal && std::abs(t) < r.b - kHalfDiagonal) return 1.0;
  Polygon poly, tmp;
  poly.n = 4;
  const double ex = r.cos_t, ey = r.sin_t;   // first side's direction
  const double fx = -r.sin_t, fy = r.cos_t;  // second side's
  const double sa[4] = {-1, 1, 1, -1}, sb[4] = {-1, -1, 1, 1};
  for (int k = 0; k < 4; ++k)
    poly.p[static_cast<std::size_t>(k)] = {r.u + sa[k] * r.a * ex + sb[k] * r.b * fx,
                                           r.v + sa[k] * r.a * ey + sb[k] * r.b * fy};
  clip(poly, tmp, [&](const Point& q) { return q.x - x0; });
  clip(tmp, poly, [&](const Point& q) { return x0 + 1.0 - q.x; });
  clip(poly, tmp, [&](const Point& q) { return q.y - y0; });
  clip(tmp, poly, [&](const Point& q) { return y0 + 1.0 - q.y; });
  double area2 = 0.0;
  for (int i = 0; i < poly.n; ++i) {
    const Point& a = poly.p[static_cast<std::size_t>(i)];
    const Point& b = poly.p[static_cast<std::size_t>((i + 1) % poly.n)];
    area2 += a.x * b.y - b.x * a.y;
  }
  return std::clamp(0.5 * std::abs(area2), 0.0, 1.0);
}

}  // namespace mc::imaging
