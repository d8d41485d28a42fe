#include "microcobot/tweezers/amplifier.h"

#include <cmath>

#include "microcobot/core/error.h"

namespace mc::tweezers {

AmplifierResult amplifier_expansion(double length_m, double stroke_m, double e_m, double a_m) {
  require_positive(length_m, "length_m");
  require_positive(stroke_m, "stroke_m");
  require_non_negative(e_m, "e_m");
  require_positive(a_m, "a_m");
  const double le = length_m + 2.0 * e_m;  // eq. A.7
  require(stroke_m < le, "stroke_m", "must be smaller than the amplifier length L + 2e", stroke_m);
  // Eq. A.8; the argument is > a^2 because dL < L_e.
  const double da = std::sqrt(a_m * a_m + 0.5 * le * stroke_m - 0.25 * stroke_m * stroke_m) - a_m;
  return {2.0 * da, 2.0 * da / stroke_m};
}

}  // namespace mc::tweezers
