#pragma once
/// @file
/// The objective's figures and its point-spread function through focus.
///
/// Figures (thesis §1.1.2; Inoué & Spring, "Video Microscopy", 2nd ed., 1997, ch. 2):
///   lateral resolution (Rayleigh)   r   = 0.61 lambda / NA
///   depth of field                  DOF = lambda n / NA^2 + n e / (M NA)   (e: pixel pitch)
///   field of view                   W e / M  x  H e / M
///
/// PSF model (docs/concepts/vision.md, "Image formation"): a Gaussian whose width is calibrated on the
/// scalar diffraction integral of an aberration-free circular pupil with defocus (Born & Wolf,
/// "Principles of Optics", 7th ed., §8.8): at each defocus dz the Gaussian has the same
/// sharpness integral  S(dz) = ∫ I^2 d^2x = ∫ |OTF|^2 d^2k  as the diffraction PSF, i.e.
///     sigma(dz)^2 = 1 / (4 pi S(dz)).
/// The OTF of the defocused pupil is its autocorrelation (Hopkins, Proc. R. Soc. A 231, 1955):
/// with the paraxial defocus aberration W020 = dz NA^2 / (2 n) and s in [0, 1] half the
/// normalised shift of the two pupils,
///     OTF(s) = (1/pi) ∫_{-(1-s)}^{1-s} cos(4 a s x) 2 sqrt(1 - (|x| + s)^2) dx,  a = 2 pi W020 / lambda,
/// at the spatial frequency k = 2 s NA / lambda. In focus this gives sigma = 0.2348 lambda/NA;
/// far from focus it tends to the geometric blur circle's (radius |dz| tan(theta), rms per axis
/// half of it), so one model covers the diffraction core and the geometric defocus.

#include <vector>

#include "microcobot/imaging/camera_params.h"

namespace mc::imaging {

/// The optics figures of an objective on a sensor.
struct OpticsFigures {
  double magnification = 0.0;
  double numerical_aperture = 0.0;
  double resolution_m = 0.0;     ///< 0.61 lambda / NA (Rayleigh)
  double dof_m = 0.0;            ///< lambda n / NA^2 + n e / (M NA)
  double dof_wave_m = 0.0;       ///< lambda n / NA^2 (the quarter-wave focal tolerance, x2)
  double dof_geometric_m = 0.0;  ///< n e / (M NA) (blur circle no larger than a pixel)
  double um_per_px = 0.0;        ///< pixel pitch / M, in micrometres
  double field_of_view_x_m = 0.0;
  double field_of_view_y_m = 0.0;
  double psf_sigma_m = 0.0;  ///< in-focus Gaussian PSF sigma (the model's)
  double psf_fwhm_m = 0.0;   ///< 2 sqrt(2 ln 2) sigma
  double airy_fwhm_m = 0.0;  ///< the Airy pattern's FWHM, 0.5145 lambda / NA
};

OpticsFigures optics_figures(const ObjectiveParams& objective, const SensorParams& sensor);

/// The defocused PSF's Gaussian width. The table (in units of lambda/NA against W020 in waves)
/// is the same for every objective: computed once per process (a few tens of ms).
class DefocusPsf {
 public:
  explicit DefocusPsf(const ObjectiveParams& objective);
  /// Gaussian sigma [m] of the PSF of a point `dz_m` away from the focal plane.
  double sigma_m(double dz_m) const noexcept;
  /// The pupil's defocus aberration W020 = dz NA^2 / (2 n) in waves.
  double defocus_waves(double dz_m) const noexcept { return dz_m * waves_per_m_; }
  /// Sharpness integral of the diffraction PSF relative to in focus, S(W020) / S(0): the
  /// normalised variance a white texture keeps at that defocus (no pixel).
  double relative_sharpness(double w020_waves) const noexcept;

 private:
  double lambda_over_na_;
  double waves_per_m_;
  double tan_theta_;
  const std::vector<double>* sigma_table_;  ///< sigma / (lambda/NA) at W020 = i * kTableStep waves
};

}  // namespace mc::imaging
