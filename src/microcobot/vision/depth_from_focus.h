#pragma once
/// @file
/// Depth from focus (docs/concepts/vision.md, "Autofocus and depth from focus"): the height of the
/// plane of best focus of a region, from the focus measures of frames taken at known focus heights (a sweep,
/// or an Autofocus search's observations). With the focus set on it, a surface's image is sharpest, so the
/// height of the sharpness peak is the surface's height: the top of a part, the tips of the gripper (Nayar &
/// Nakagawa, "Shape from focus", IEEE PAMI 16:824, 1994).
///
/// The peak: a least-squares parabola y(z) = c0 + c1 z + c2 z^2 through the samples around the
/// sharpest one (those whose measure is at least `peak_fraction` of the largest, and at least its
/// nearest neighbour on either side), its vertex z* = -c1 / (2 c2). Two peak models:
///   kLorentzian  y = 1 / F, weights F^4 (F's noise, relative, carried to 1/F): exact when
///                F ∝ 1 / sigma(z)^2 with sigma^2 quadratic in z, as the normalised variance of
///                a fine texture under a Gaussian PSF is (optics.h: S = 1/(4 pi sigma^2) and
///                the geometric blur sigma ∝ |z - z*|) — the default;
///   kGaussian    y = ln F, weights F^2 (Nayar & Nakagawa §5's Gaussian interpolation, exact for
///                F = F0 exp(-(z - z*)^2 / (2 w^2))).
/// With three samples either reduces to the parabola through them.

#include <span>

namespace mc::vision {

/// A focus measure taken with the focal plane at z_m.
struct FocusSample {
  double z_m = 0.0;
  double sharpness = 0.0;
};

enum class PeakModel { kLorentzian, kGaussian };

/// Below this ratio of the largest to the smallest focus measure a sweep shows no peak (a flat,
/// textureless region: the measures differ by the sensor's noise only, well under 1 %).
inline constexpr double kDefaultMinFocusContrast = 1.1;

struct FocusPeakParams {
  double min_contrast = kDefaultMinFocusContrast;
  double peak_fraction = 0.5;  ///< samples with F >= peak_fraction x max F enter the fit
  PeakModel model = PeakModel::kLorentzian;
};

struct FocusPeak {
  /// A peak was found: the sharpest sample has a neighbour on either side and the measures rise
  /// to it by at least the minimum contrast.
  bool found = false;
  double z_m = 0.0;         ///< the fitted peak's height (when !found: the sharpest sample's)
  double sharpness = 0.0;   ///< the largest measure
  double contrast = 0.0;    ///< largest / smallest measure (infinite when the smallest is 0)
  int fitted = 0;           ///< samples in the fit
  const char* reason = "";  ///< why no peak was found ("" when found)
};

/// The plane of best focus from `samples` (any order; allocation-free), all of one focus measure
/// (of an Autofocus's observations, those whose observation_metrics() is its fine metric). Throws
/// InvalidInput for a non-finite height or a negative or non-finite measure.
FocusPeak focus_peak(std::span<const FocusSample> samples, const FocusPeakParams& params = {});

/// The vertex of the parabola through (z_i, y_i), i = a, b, c (distinct heights); the middle
/// sample's height when the three are collinear.
double parabola_vertex(double za, double ya, double zb, double yb, double zc, double yc);

}  // namespace mc::vision
