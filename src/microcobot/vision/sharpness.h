#pragma once
/// @file
/// Focus measures (sharpness) of a camera frame or of a rectangle of it
/// (docs/concepts/vision.md, "Autofocus and depth from focus"). Each is largest when the imaged surface is in
/// focus: defocus is a low-pass filter (optics.h, DefocusPsf), so it removes image variance and gradient
/// energy. The three are the ones Sun, Duthaler & Nelson compare ("Autofocusing in computer microscopy:
/// selecting the optimal focus algorithm", Microsc. Res. Tech. 65:139, 2004), over the N pixels I(x, y) of
/// the region with mean mu:
///
///   normalised variance (Groen, Young & Ligthart, Cytometry 6:81, 1985; Sun et al. eq. 14):
///       F = 1 / (N mu) sum (I - mu)^2
///   Tenengrad (Tenenbaum 1970; Krotkov, IJCV 1:223, 1987; Sun et al. eq. 6), Sobel gradients
///   Gx, Gy over the region's interior (the N' pixels whose 3 x 3 neighbourhood is in the region):
///       F = 1 / N' sum (Gx^2 + Gy^2)  over the pixels with Gx^2 + Gy^2 > T
///   Brenner gradient (Brenner et al., J. Histochem. Cytochem. 24:100, 1976; Sun et al. eq. 2),
///   the horizontal difference at two pixels over the N'' pixel pairs inside the region:
///       F = 1 / N'' sum (I(x + 2, y) - I(x, y))^2
///
/// The normalised variance is the default: Sun et al. rank it best overall (accuracy, range,
/// noise) and, dividing by the mean, it does not change with the illumination. Evaluation
/// allocates nothing and leaves the frame untouched; the regions are validated first.

#include <string>

#include "microcobot/imaging/pixel_roi.h"
#include "microcobot/imaging/sensor_model.h"

namespace mc::vision {

enum class FocusMetric { kNormalizedVariance, kTenengrad, kBrenner };

/// "normalized-variance", "tenengrad" or "brenner" (the CLI's spelling).
const char* focus_metric_name(FocusMetric metric);
/// Parses a metric's name; throws InvalidInput listing the known names.
FocusMetric parse_focus_metric(const std::string& name);

/// Throws InvalidInput (one line naming the ROI and the image's size) unless `roi` is non-empty,
/// at least `min_side` pixels on each side and lies inside a `width` x `height` image.
void validate_roi(const imaging::PixelRoi& roi, int width, int height, int min_side = 1);

/// Normalised variance of the region (see above); 0 for a black region.
double normalized_variance(const imaging::Frame& frame, const imaging::PixelRoi& roi);
/// Tenengrad with the threshold `threshold` on the squared Sobel magnitude [DN^2]; needs a region
/// of at least 3 x 3 pixels.
double tenengrad(const imaging::Frame& frame, const imaging::PixelRoi& roi, double threshold = 0.0);
/// Brenner gradient; needs a region at least 3 pixels wide.
double brenner(const imaging::Frame& frame, const imaging::PixelRoi& roi);

/// The options of a focus measure evaluated by name.
struct SharpnessParams {
  std::string metric =
      "normalized-variance";         ///< the focus measure: normalized-variance, tenengrad or brenner
  double tenengrad_threshold = 0.0;  ///< T [DN^2]: gradients at or under it are left out (noise)

  template <class V>
  void visit(V& v) {
    v("metric", metric);
    v("tenengrad_threshold", tenengrad_threshold);
  }
  void validate() const;
};

/// The measure `metric` of `roi` in `frame` (validates the region).
double sharpness(const imaging::Frame& frame, const imaging::PixelRoi& roi, FocusMetric metric,
                 double tenengrad_threshold = 0.0);

}  // namespace mc::vision
