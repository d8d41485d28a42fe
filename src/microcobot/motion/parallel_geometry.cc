#include "microcobot/motion/parallel_geometry.h"

#include <cmath>
#include <numbers>

#include "microcobot/core/error.h"

namespace mc::motion {

void ParallelGeometryParams::validate() const {
  require(std::isfinite(base_radius_m) && base_radius_m >= 1e-3 && base_radius_m <= 0.5, "base_radius_m",
          "must be within [1 mm, 500 mm]", base_radius_m);
  require(std::isfinite(platform_radius_m) && platform_radius_m >= 1e-3 && platform_radius_m < base_radius_m,
          "platform_radius_m", "must be within [1 mm, base_radius_m)", platform_radius_m);
  require(std::isfinite(joint_height_m) && joint_height_m >= 1e-3 && joint_height_m <= 0.5, "joint_height_m",
          "must be within [1 mm, 500 mm]", joint_height_m);
  require(std::isfinite(top_offset_m) && top_offset_m >= 0.0 && top_offset_m <= 0.5, "top_offset_m",
          "must be within [0, 500 mm]", top_offset_m);
  // The stroke must keep the carriage's joint outside the platform's radius: beyond it the legs
  // would cross the vertical.
  require(std::isfinite(stroke_m) && stroke_m > 0.0 && stroke_m < 2.0 * (base_radius_m - platform_radius_m),
          "stroke_m", "must be within (0, 2 (base_radius_m - platform_radius_m))", stroke_m);
  require(std::isfinite(spherical_limit_rad) && spherical_limit_rad > 0.0 && spherical_limit_rad < 0.5 * M_PI,
          "spherical_limit_rad", "must be within (0, pi/2)", spherical_limit_rad);
  require(std::isfinite(revolute_limit_rad) && revolute_limit_rad > 0.0 && revolute_limit_rad < 0.5 * M_PI,
          "revolute_limit_rad", "must be within (0, pi/2)", revolute_limit_rad);
  require(std::isfinite(min_conditioning) && min_conditioning > 0.0 && min_conditioning < 1.0,
          "min_conditioning", "must be within (0, 1)", min_conditioning);
}

double ParallelGeometryParams::leg_length_m() const noexcept {
  return std::hypot(base_radius_m - platform_radius_m, joint_height_m);
}

ParallelGeometry::ParallelGeometry(const ParallelGeometryParams& p) : params(p) {
  params.validate();
  leg_length_m = params.leg_length_m();
  home_height_m = params.home_height_m();
  const Eigen::Vector3d ez = Eigen::Vector3d::UnitZ();
  for (int i = 0; i < kParallelLegs; ++i) {
    const double phi = 0.5 * std::numbers::pi + i * 2.0 * std::numbers::pi / kParallelLegs;
    LegGeometry& g = legs[i];
    g.e_r = {std::cos(phi), std::sin(phi), 0.0};
    g.e_t = {-std::sin(phi), std::cos(phi), 0.0};
    g.base_m = params.base_radius_m * g.e_r;
    g.platform_m = params.platform_radius_m * g.e_r - params.top_offset_m * ez;
    g.axis = g.e_t;
    const Eigen::Vector3d joint_home = g.platform_m + home_height_m * ez;  // in {B}
    g.home_leg = (joint_home - g.base_m) / leg_length_m;
  }
}

}  // namespace mc::motion
