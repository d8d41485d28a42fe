#include "microcobot/stickslip/stickslip_params.h"

#include <cmath>

#include "microcobot/core/error.h"

namespace mc::stickslip {

void SliderParams::validate() const {
  require_positive(mass_kg, "slider.mass_kg");
  require_positive(stroke_m, "slider.stroke_m");
  require(std::isfinite(initial_position_m) && std::abs(initial_position_m) <= 0.5 * stroke_m,
          "slider.initial_position_m", "must lie between the end stops (|x| <= stroke_m / 2)",
          initial_position_m);
  require(std::isfinite(load_force_N), "slider.load_force_N", "must be finite", load_force_N);
}

void IntegratorParams::validate() const {
  require(std::isfinite(dt_s) && dt_s > 0.0 && dt_s <= 1e-4, "integrator.dt_s", "must be in (0, 1e-4] s",
          dt_s);
  require(substeps >= 1 && substeps <= 1000, "integrator.substeps", "must be in [1, 1000]", substeps);
  require_positive(substep_edge_V, "integrator.substep_edge_V");
  require_non_negative(substep_strain_fraction, "integrator.substep_strain_fraction");
}

void StickSlipParams::validate() const {
  pe.validate();
  hysteresis.validate();
  friction.validate();
  slider.validate();
  breakaway.validate();
  drive.validate();
  integrator.validate();
}

}  // namespace mc::stickslip
