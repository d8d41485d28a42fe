#pragma once
/// @file
/// The microscope camera's parameters: the sensor, the objective and the
/// illumination. Plain Params structs (visit/validate) with the defaults of a real set-up: a
/// 1.3 MP global-shutter CMOS camera (e2v EV76C560: 1280 x 1024, 5.3 um pixels) behind an
/// infinity-corrected long-working-distance objective (Mitutoyo M Plan Apo series, 200 mm tube
/// lens). Sources in docs/parameters.md ("Camera and objectives").

#include <string>
#include <vector>

#include "microcobot/core/params.h"

namespace mc::imaging {

/// The image sensor and its read-out (EMVA 1288's photon-transfer quantities).
struct SensorParams {
  int width_px = 1280;            ///< active pixels per row
  int height_px = 1024;           ///< active rows
  double pixel_pitch_m = 5.3e-6;  ///< the pixels' pitch (square pixels)
  int bit_depth = 12;             ///< 8 to 16 bits per pixel
  double exposure_s = 10e-3;      ///< exposure time (at most the frame period)
  /// Analog gain: 1 maps the full well to the full digital scale (the system gain
  /// K = gain (2^bits - 1) / full_well DN per electron).
  double gain = 1.0;
  double full_well_e = 10000.0;
  double read_noise_e = 10.0;          ///< temporal dark noise, rms electrons
  double dark_current_e_per_s = 20.0;  ///< at 25 degC
  double frame_rate_Hz = 30.0;

  template <class V>
  void visit(V& v) {
    v("width_px", width_px);
    v("height_px", height_px);
    v("pixel_pitch_m", pixel_pitch_m);
    v("bit_depth", bit_depth);
    v("exposure_s", exposure_s);
    v("gain", gain);
    v("full_well_e", full_well_e);
    v("read_noise_e", read_noise_e);
    v("dark_current_e_per_s", dark_current_e_per_s);
    v("frame_rate_Hz", frame_rate_Hz);
  }
  void validate() const;
  /// Largest digital number, 2^bit_depth - 1.
  int max_dn() const { return (1 << bit_depth) - 1; }
  /// System gain K [DN per electron].
  double system_gain_dn_per_e() const { return gain * max_dn() / full_well_e; }
};

/// An infinity-corrected objective (with its tube lens: the magnification on the sensor).
struct ObjectiveParams {
  std::string name = "20x";             ///< its label in the console and the recordings
  double magnification = 20.0;          ///< lateral magnification on the sensor
  double numerical_aperture = 0.42;     ///< NA: resolution and depth of field
  double working_distance_m = 20.0e-3;  ///< front lens to focal plane
  double wavelength_m = 550e-9;         ///< centre of the illumination's band (green)
  double immersion_index = 1.0;         ///< refractive index between the objective and the object (air)

  template <class V>
  void visit(V& v) {
    v("name", name);
    v("magnification", magnification);
    v("numerical_aperture", numerical_aperture);
    v("working_distance_m", working_distance_m);
    v("wavelength_m", wavelength_m);
    v("immersion_index", immersion_index);
  }
  void validate() const;
};

/// The objectives of the turret: Mitutoyo M Plan Apo 2x/0.055, 5x/0.14, 10x/0.28, 20x/0.42,
/// 50x/0.55 (catalogue values, docs/parameters.md).
std::vector<ObjectiveParams> objective_table();
/// The objective named `name` ("2x" ... "50x"); throws UsageError listing the known names.
ObjectiveParams objective_by_name(const std::string& name);

/// Brightfield illumination through the objective (reflected, epi) or through the substrate
/// from below (transmitted).
struct IlluminationParams {
  std::string mode = "reflected";  ///< "reflected" or "transmitted"
  /// Photo-electrons per second a pixel collects from a perfect reflector (or a clear
  /// transmission path): with the default 10 ms exposure a white object fills 80 % of the well.
  double electrons_per_s = 8.0e5;

  template <class V>
  void visit(V& v) {
    v("mode", mode);
    v("electrons_per_s", electrons_per_s);
  }
  void validate() const;
  bool transmitted() const { return mode == "transmitted"; }
};

struct CameraParams {
  SensorParams sensor;
  ObjectiveParams objective;
  IlluminationParams illumination;
  /// The stage point imaged at the sensor's centre (the microscope's optical axis) [m].
  double view_center_x_m = 0.0;
  double view_center_y_m = 0.0;

  template <class V>
  void visit(V& v) {
    v("sensor", sensor);
    v("objective", objective);
    v("illumination", illumination);
    v("view_center_x_m", view_center_x_m);
    v("view_center_y_m", view_center_y_m);
  }
  void validate() const;
  /// Object-space size of a pixel, pixel_pitch / M [m].
  double pixel_size_m() const { return sensor.pixel_pitch_m / objective.magnification; }
};

}  // namespace mc::imaging
