#include "microcobot/imaging/camera_params.h"

#include <cmath>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"

namespace mc::imaging {

void SensorParams::validate() const {
  require(width_px >= 8 && width_px <= 8192, "width_px", "must be within [8, 8192]", width_px);
  require(height_px >= 8 && height_px <= 8192, "height_px", "must be within [8, 8192]", height_px);
  require(pixel_pitch_m > 0.0 && pixel_pitch_m < 1e-4, "pixel_pitch_m", "must be within (0, 1e-4)",
          pixel_pitch_m);
  require(bit_depth >= 8 && bit_depth <= 16, "bit_depth", "must be within [8, 16]", bit_depth);
  require(exposure_s > 0.0 && exposure_s <= 10.0, "exposure_s", "must be within (0, 10]", exposure_s);
  require(gain > 0.0 && gain <= 1000.0, "gain", "must be within (0, 1000]", gain);
  require(full_well_e >= 100.0 && full_well_e <= 1e7, "full_well_e", "must be within [100, 1e7]",
          full_well_e);
  require(read_noise_e >= 0.0 && read_noise_e < full_well_e, "read_noise_e",
          "must be within [0, full_well_e)", read_noise_e);
  require(dark_current_e_per_s >= 0.0 && std::isfinite(dark_current_e_per_s), "dark_current_e_per_s",
          "must be finite and >= 0", dark_current_e_per_s);
  require(frame_rate_Hz > 0.0 && frame_rate_Hz <= 10000.0, "frame_rate_Hz", "must be within (0, 10000]",
          frame_rate_Hz);
}

void ObjectiveParams::validate() const {
  require(magnification > 0.0 && magnification <= 1000.0, "magnification", "must be within (0, 1000]",
          magnification);
  require(immersion_index >= 1.0 && immersion_index <= 2.0, "immersion_index", "must be within [1, 2]",
          immersion_index);
  require(numerical_aperture > 0.0 && numerical_aperture < immersion_index, "numerical_aperture",
          "must be within (0, immersion_index)", numerical_aperture);
  require(working_distance_m > 0.0 && working_distance_m < 1.0, "working_distance_m", "must be within (0, 1)",
          working_distance_m);
  require(wavelength_m >= 200e-9 && wavelength_m <= 2000e-9, "wavelength_m", "must be within [2e-7, 2e-6]",
          wavelength_m);
}

std::vector<ObjectiveParams> objective_table() {
  // Mitutoyo M Plan Apo (infinity-corrected, 200 mm tube lens): magnification, NA, working distance.
  const struct {
    const char* name;
    double m, na, wd_mm;
  } rows[] = {{"2x", 2, 0.055, 34.0},
              {"5x", 5, 0.14, 34.0},
              {"10x", 10, 0.28, 33.5},
              {"20x", 20, 0.42, 20.0},
              {"50x", 50, 0.55, 13.0}};
  std::vector<ObjectiveParams> out;
  for (const auto& r : rows) {
    ObjectiveParams o;
    o.name = r.name;
    o.magnification = r.m;
    o.numerical_aperture = r.na;
    o.working_distance_m = r.wd_mm * 1e-3;
    out.push_back(o);
  }
  return out;
}

ObjectiveParams objective_by_name(const std::string& name) {
  std::string known;
  for (const ObjectiveParams& o : objective_table()) {
    if (o.name == name) return o;
    known += (known.empty() ? "" : ", ") + o.name;
  }
  throw UsageError("objective '" + excerpt(name) + "' is not one of the turret's (" + known + ")");
}

void IlluminationParams::validate() const {
  require(mode == "reflected" || mode == "transmitted", "mode",
          "must be reflected or transmitted, not '" + excerpt(mode) + "'");
  require(electrons_per_s >= 0.0 && electrons_per_s <= 1e12, "electrons_per_s", "must be within [0, 1e12]",
          electrons_per_s);
}

void CameraParams::validate() const {
  sensor.validate();
  objective.validate();
  illumination.validate();
  require(std::isfinite(view_center_x_m) && std::isfinite(view_center_y_m), "view_center_m",
          "must be finite");
}

}  // namespace mc::imaging
