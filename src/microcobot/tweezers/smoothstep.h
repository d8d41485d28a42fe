#pragma once
/// @file
/// The cubic smoothstep s(x) = 3x^2 - 2x^3 on [0, 1] (0 below, 1 above) and its slope
/// s'(x) = 6x(1 - x): the ramps with which the tweezers' control modes and the virtual cube blend
/// one behaviour into the next, continuous in value and slope at both ends.

#include <algorithm>

namespace mc::tweezers {

inline double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3 - 2 * x);
}

inline double smoothstep_rate(double x) { return (x <= 0 || x >= 1) ? 0.0 : 6 * x * (1 - x); }

}  // namespace mc::tweezers
