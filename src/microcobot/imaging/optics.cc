#include "microcobot/imaging/optics.h"

#include <algorithm>
#include <cmath>

namespace mc::imaging {

namespace {

// ∫_0^1 OTF(s)^2 2 pi s ds for the pupil with defocus `w020_waves` (s: half the normalised shift).
// Dimensionless; the sharpness integral is (2 NA / lambda)^2 times it.
double otf_energy(double w020_waves) {
  constexpr int kS = 100, kX = 200;
  const double a = 2.0 * M_PI * w020_waves;
  double sum = 0.0;
  for (int i = 0; i < kS; ++i) {
    const double s = (i + 0.5) / kS;
    const double half = 1.0 - s;
    double otf = 0.0;
    const double dx = 2.0 * half / kX;
    for (int j = 0; j < kX; ++j) {
      const double x = -half + (j + 0.5) * dx;
      const double r = std::abs(x) + s;
      otf += std::cos(4.0 * a * s * x) * 2.0 * std::sqrt(std::max(0.0, 1.0 - r * r)) * dx;
    }
    otf /= M_PI;
    sum += otf * otf * 2.0 * M_PI * s / kS;
  }
  return sum;
}

constexpr double kTableStep = 0.05;  // waves

// sigma / (lambda/NA) at W020 = i kTableStep, i < 161 (8 waves); beyond, the geometric continuation.
const std::vector<double>& sigma_table() {
  static const std::vector<double> table = [] {
    std::vector<double> t(161);
    for (std::size_t i = 0; i < t.size(); ++i) {
      const double energy =
          4.0 * otf_energy(static_cast<double>(i) * kTableStep);  // (2 NA/lambda)^2, lambda/NA = 1
      t[i] = std::sqrt(1.0 / (4.0 * M_PI * energy));
    }
    return t;
  }();
  return table;
}

}  // namespace

OpticsFigures optics_figures(const ObjectiveParams& o, const SensorParams& s) {
  OpticsFigures f;
  const double lambda = o.wavelength_m, na = o.numerical_aperture, n = o.immersion_index, m = o.magnification;
  f.magnification = m;
  f.numerical_aperture = na;
  f.resolution_m = 0.61 * lambda / na;
  f.dof_wave_m = lambda * n / (na * na);
  f.dof_geometric_m = n * s.pixel_pitch_m / (m * na);
  f.dof_m = f.dof_wave_m + f.dof_geometric_m;
  f.um_per_px = s.pixel_pitch_m / m * 1e6;
  f.field_of_view_x_m = s.width_px * s.pixel_pitch_m / m;
  f.field_of_view_y_m = s.height_px * s.pixel_pitch_m / m;
  f.psf_sigma_m = DefocusPsf(o).sigma_m(0.0);
  f.psf_fwhm_m = 2.0 * std::sqrt(2.0 * std::log(2.0)) * f.psf_sigma_m;
  // Airy: [2 J1(v)/v]^2 = 1/2 at v = 1.6163, v = 2 pi NA r / lambda.
  f.airy_fwhm_m = 2.0 * 1.6163 / (2.0 * M_PI) * lambda / na;
  return f;
}

DefocusPsf::DefocusPsf(const ObjectiveParams& o)
    : lambda_over_na_(o.wavelength_m / o.numerical_aperture),
      waves_per_m_(o.numerical_aperture * o.numerical_aperture / (2.0 * o.immersion_index * o.wavelength_m)),
      tan_theta_(std::tan(std::asin(o.numerical_aperture / o.immersion_index))),
      sigma_table_(&sigma_table()) {}

double DefocusPsf::sigma_m(double dz_m) const noexcept {
  const double w = std::abs(dz_m) * waves_per_m_;
  const double pos = w / kTableStep;
  const auto last = static_cast<double>(sigma_table_->size() - 1);
  if (pos >= last) {
    // Geometric continuation: the blur circle's rms per axis, |dz| tan(theta) / 2, in quadrature
    // with what the table's end holds beyond it (matched at the end so the curve is continuous).
    const double dz_end = last * kTableStep / waves_per_m_;
    const double end = sigma_table_->back() * lambda_over_na_;
    const double g_end = 0.5 * dz_end * tan_theta_, g = 0.5 * std::abs(dz_m) * tan_theta_;
    return std::sqrt(std::max(end * end - g_end * g_end, 0.0) + g * g);
  }
  const auto i = static_cast<std::size_t>(pos);
  const double t = pos - static_cast<double>(i);
  return ((1.0 - t) * (*sigma_table_)[i] + t * (*sigma_table_)[i + 1]) * lambda_over_na_;
}

double DefocusPsf::relative_sharpness(double w020_waves) const noexcept {
  const double s0 = sigma_table_->front() * lambda_over_na_;
  const double s = sigma_m(w020_waves / waves_per_m_);
  return (s0 * s0) / (s * s);
}

}  // namespace mc::imaging
