#include "microcobot/vision/localisation_bound.h"

#include <cmath>
#include <string>

#include "microcobot/core/error.h"

namespace mc::vision {

LocalisationBound translation_bound(const std::function<std::vector<float>(double, double)>& expected_e,
                                    const imaging::SensorParams& sensor, double exposure_s, double gain,
                                    const imaging::PixelRoi& roi, double step_px) {
  if (roi.width < 1 || roi.height < 1 || roi.x < 0 || roi.y < 0 || roi.x + roi.width > sensor.width_px ||
      roi.y + roi.height > sensor.height_px)
    throw InvalidInput("localisation bound: ROI x " + std::to_string(roi.x) + ", y " + std::to_string(roi.y) +
                       ", " + std::to_string(roi.width) + "x" + std::to_string(roi.height) +
                       " not inside the sensor");
  if (!(step_px > 0.0) || !std::isfinite(step_px))
    throw InvalidInput("localisation bound: step " + std::to_string(step_px) + " px must be finite and > 0");
  const std::vector<float> centre = expected_e(0.0, 0.0);
  const std::vector<float> u_plus = expected_e(step_px, 0.0), u_minus = expected_e(-step_px, 0.0);
  const std::vector<float> v_plus = expected_e(0.0, step_px), v_minus = expected_e(0.0, -step_px);
  const double k = gain * sensor.max_dn() / sensor.full_well_e;  // DN per electron
  const double dark = sensor.dark_current_e_per_s * exposure_s;
  const double read2 = sensor.read_noise_e * sensor.read_noise_e;
  double fuu = 0.0, fuv = 0.0, fvv = 0.0;
  for (int i = roi.y; i < roi.y + roi.height; ++i)
    for (int j = roi.x; j < roi.x + roi.width; ++j) {
      const std::size_t p = static_cast<std::size_t>(i) * static_cast<std::size_t>(sensor.width_px) +
                            static_cast<std::size_t>(j);
      const double du = k * (double(u_plus[p]) - double(u_minus[p])) / (2.0 * step_px);
      const double dv = k * (double(v_plus[p]) - double(v_minus[p])) / (2.0 * step_px);
      const double var = k * k * (double(centre[p]) + dark + read2) + 1.0 / 12.0;
      fuu += du * du / var;
      fuv += du * dv / var;
      fvv += dv * dv / var;
    }
  const double det = fuu * fvv - fuv * fuv;
  if (!(det > 0.0) || !std::isfinite(det))
    throw InvalidInput("localisation bound: the ROI holds no information on the translation (no edge)");
  return {std::sqrt(fvv / det), std::sqrt(fuu / det)};
}

}  // namespace mc::vision
