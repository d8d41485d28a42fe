#include "microcobot/motion/rotary_axis.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::motion {

void RotaryAxisParams::validate() const {
  require(std::isfinite(radius_m) && radius_m >= 0.5e-3 && radius_m <= 0.1, "radius_m",
          "must be within [0.5 mm, 100 mm]", radius_m);
  require(std::isfinite(max_speed_rad_s) && max_speed_rad_s > 0.0 && max_speed_rad_s <= 10.0,
          "max_speed_rad_s", "must be within (0, 10] rad/s", max_speed_rad_s);
  require(std::isfinite(home_rad) && std::abs(home_rad) <= M_PI, "home_rad", "must be within [-pi, pi] rad",
          home_rad);
}

}  // namespace mc::motion
