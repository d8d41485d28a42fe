#pragma once
/// @file
/// Sub-pixel template tracking: a patch of a first frame (a part, a hole, a
/// pin, the gripper's tip) found again in each later frame.
///
///  1. Coarse: normalised cross-correlation (OpenCV matchTemplate, TM_CCOEFF_NORMED) over a
///     window around the predicted position (last position + last displacement); its peak is the
///     integer-pixel match and the confidence.
///  2. Fine: the enhanced correlation coefficient (ECC) maximised from that match (Evangelidis &
///     Psarakis, "Parametric image alignment using enhanced correlation coefficient
///     maximization", IEEE TPAMI 30(10), 2008; OpenCV findTransformECC): a Gauss-Newton
///     alignment of the intensities, invariant to brightness and contrast, so the estimate is
///     continuous in the shift (no pixel locking of a peak fit). With `rotation` the warp is
///     Euclidean and the in-plane angle comes with the position.
///  3. Lost: a correlation below `lost_below`, or a contrast far from the template's (occluded,
///     out of the field, defocused) around the
///     prediction: the frame is then searched whole, on a 2x-decimated image; still below, the
///     target is lost and later frames are searched whole until it is re-acquired.
///
/// The position reported is the template's centre in the frame's continuous pixel coordinates
/// (pixel (row i, column j) spans [j - 1/2, j + 1/2] x [i - 1/2, i + 1/2]: its centre is (j, i)),
/// as imaging::Renderer's u_of_x/v_of_y. Not thread-safe: one tracker per camera thread. OpenCV
/// stays inside template_tracker.cc.

#include <algorithm>
#include <memory>

#include "microcobot/imaging/pixel_roi.h"
#include "microcobot/imaging/sensor_model.h"

namespace mc::vision {

struct TrackerParams {
  /// Pixels searched beyond the template on each side around the predicted position [px].
  int search_margin_px = 24;
  /// Below this normalised correlation the target is lost (and searched in the whole frame).
  double lost_below = 0.5;
  /// ... or when the match's contrast (rms) is under this fraction of the template's, or over its
  /// inverse: correlation alone would take a faint texture of the same shape for the target.
  double min_contrast_ratio = 0.5;
  int ecc_iterations = 50;
  double ecc_epsilon = 1e-6;  ///< ECC stops when its correlation grows by less than this
  /// Gaussian pre-filter of both images before ECC [px, odd; 1: none], applied with each patch's
  /// surroundings (not a padded border). 3: at 20x (PSF sigma ~1.2 px) unfiltered edges let the
  /// bilinear warp pull toward whole pixels (calibration residual 0.10-0.14 px instead of 0.04);
  /// 5 loses information (2.0-2.3x the localisation bound at 10x instead of ~1.95x pooled).
  int ecc_blur_px = 3;
  /// High-pass before ECC: a Gaussian of this sigma [px] subtracted (0: none). For a target over
  /// a background that does not move with it and is out of focus (the gripper's tips over a part
  /// 150 um below): its glow changes under the template and pulls the alignment (tool tips at
  /// 5x: worst 0.49 px rms without, 0.036 px with 1.5 px). Off by default: on a part's corner it
  /// costs precision (median 0.024 -> 0.037 px).
  double ecc_highpass_px = 0.0;
  bool rotation = false;  ///< also estimate the in-plane angle (Euclidean warp)

  template <class V>
  void visit(V& v) {
    v("search_margin_px", search_margin_px);
    v("lost_below", lost_below);
    v("min_contrast_ratio", min_contrast_ratio);
    v("ecc_iterations", ecc_iterations);
    v("ecc_epsilon", ecc_epsilon);
    v("ecc_blur_px", ecc_blur_px);
    v("ecc_highpass_px", ecc_highpass_px);
    v("rotation", rotation);
  }
  void validate() const;
};

/// The high-pass for the gripper's tips (TrackerParams::ecc_highpass_px) [px]: chosen on the
/// tool-tracking tuning cases (docs/parameters.md "Tracking the tool's tips").
inline constexpr double kToolTipHighpass_px = 1.5;

/// The side of the tips' template in the object [m]: the tips' ends and the gap between them,
/// whatever the objective (chosen on the tool-tracking tuning cases at 2x-50x, docs/parameters.md
/// "Tracking the tool's tips"). A side in pixels fixed at every objective held the two tips' ends
/// at 5x and 10x but, at 50x, only a stretch of the fingers' parallel sides, along which the
/// match slides (45 px off, every frame found).
inline constexpr double kToolTemplateSide_m = 50e-6;
/// The fewest pixels a template side gets: below, ECC has too few gradients for a hundredth of a
/// pixel (the 96 px side the tracker was tuned with at 5x and 10x).
inline constexpr int kMinTemplateSide_px = 96;

/// A template of `side_m` in the object as pixels of `pixel_m`: at least kMinTemplateSide_px, at
/// most half the frame's smaller side (`width_px`, `height_px`).
inline int template_side_px(double side_m, double pixel_m, int width_px, int height_px) {
  const double px = side_m / pixel_m;
  const int most = std::max(kMinTemplateSide_px, std::min(width_px, height_px) / 2);
  if (!(px > kMinTemplateSide_px)) return kMinTemplateSide_px;  // also NaN
  return px >= most ? most : static_cast<int>(px + 0.5);
}

/// TrackerParams for the gripper's tips: the defaults with kToolTipHighpass_px.
inline TrackerParams tool_tip_tracker_params() {
  TrackerParams p;
  p.ecc_highpass_px = kToolTipHighpass_px;
  return p;
}

/// One frame's estimate.
struct TrackEstimate {
  double u_px = 0.0;        ///< the template centre's column (continuous)
  double v_px = 0.0;        ///< ... and row
  double angle_rad = 0.0;   ///< in-plane rotation from the template (image axes, counter-clockwise as seen)
  double confidence = 0.0;  ///< the match's normalised correlation, [-1, 1]
  bool found = false;       ///< false: lost (the position is the last known one)
  bool reacquired = false;  ///< found by a whole-frame search after being lost
};

class TemplateTracker {
 public:
  explicit TemplateTracker(const TrackerParams& params = {});
  ~TemplateTracker();
  TemplateTracker(TemplateTracker&&) noexcept;
  TemplateTracker& operator=(TemplateTracker&&) noexcept;

  const TrackerParams& params() const { return params_; }

  /// Takes the template from `frame` inside `roi` and tracks from there. Throws mc::InvalidInput
  /// naming the ROI when it is empty, smaller than 8x8 or not inside the frame, or when the patch
  /// has no contrast (nothing to track).
  void set_template(const imaging::Frame& frame, const imaging::PixelRoi& roi);
  bool has_template() const;
  /// Where the template is in `frame` (same size as the template's frame, else InvalidInput),
  /// searched around the last position plus the last frame-to-frame displacement.
  TrackEstimate track(const imaging::Frame& frame);
  /// The same, searched around a caller's prediction of the template centre (a commanded stage
  /// move seen through the calibration, a servo's expected motion). Non-finite: InvalidInput.
  TrackEstimate track_near(const imaging::Frame& frame, double u_px, double v_px);
  /// The same, searched around the segment between two predictions (a finger closing on a part
  /// that may stop it anywhere between where its drive puts it and where it was).
  TrackEstimate track_along(const imaging::Frame& frame, double u0_px, double v0_px, double u1_px,
                            double v1_px);
  /// Whether the template centred at (u_px, v_px) lies wholly inside a `width_px` x `height_px`
  /// frame (false without a template). Searching for a target predicted out of the frame is
  /// a whole-frame search that cannot find it.
  bool fits(double u_px, double v_px, int width_px, int height_px) const noexcept;
  /// The last estimate (the template's own position before the first track()).
  const TrackEstimate& last() const { return last_; }

 private:
  struct Images;  // OpenCV's matrices, kept out of this header
  TrackEstimate track_around(const imaging::Frame& frame, double u0_px, double v0_px, double u1_px,
                             double v1_px, bool whole);
  TrackerParams params_;
  std::unique_ptr<Images> images_;
  TrackEstimate last_;
  int templ_width_ = 0, templ_height_ = 0;
  double du_ = 0.0, dv_ = 0.0;  // the last frame-to-frame displacement (prediction)
  bool lost_ = false;
};

}  // namespace mc::vision
