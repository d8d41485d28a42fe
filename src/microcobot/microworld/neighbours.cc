#include "microcobot/microworld/neighbours.h"

#include <cmath>
#include <limits>

namespace mc::microworld {
namespace {

// The projection's half-length of a rectangle on the unit axis n.
double radius_on(const Footprint& f, const Eigen::Vector2d& u0, const Eigen::Vector2d& u1,
                 const Eigen::Vector2d& n) noexcept {
  return f.half.x() * std::abs(u0.dot(n)) + f.half.y() * std::abs(u1.dot(n));
}

}  // namespace

double overlap(const Footprint& a, const Footprint& b, Eigen::Vector2d& out_of_a) noexcept {
  const Eigen::Vector2d a0(std::cos(a.yaw_rad), std::sin(a.yaw_rad)), a1(-a0.y(), a0.x());
  const Eigen::Vector2d b0(std::cos(b.yaw_rad), std::sin(b.yaw_rad)), b1(-b0.y(), b0.x());
  const Eigen::Vector2d d = b.centre - a.centre;
  double least = std::numeric_limits<double>::infinity();
  out_of_a.setZero();
  for (const Eigen::Vector2d& n : {a0, a1, b0, b1}) {
    const double dist = d.dot(n);
    const double o = radius_on(a, a0, a1, n) + radius_on(b, b0, b1, n) - std::abs(dist);
    if (o <= 0.0) {
      out_of_a.setZero();
      return 0.0;  // a separating axis
    }
    if (o < least) {
      least = o;
      out_of_a = dist >= 0.0 ? n : Eigen::Vector2d(-n);
    }
  }
  return least;
}

}  // namespace mc::microworld
