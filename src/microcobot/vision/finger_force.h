#pragma once
/// @file
/// Force measured by vision (thesis Fig. 1.5, after Greminger & Nelson,
/// "Vision-based force measurement", IEEE TPAMI 26(3), 2004): the gripper's fingers are springs
/// of known stiffness k at their tips (microworld/piezo_gripper.h); the tips' deflection seen in
/// the image, times k, is the force on them.
///
///  1. Templates: each finger's tip (its outer half and its end, away from the jaw where a part
///     will touch) tracked by its own vision::TemplateTracker.
///  2. Unloaded pose: with nothing between the fingers, the tips' image columns at several
///     opening commands, a line per tip u_i(o) = a_i + b_i o (least squares). b_i is the image's
///     scale along the opening (px per metre of opening: the tip moves by half of it) and its
///     sign, so no stage calibration is needed and the objective's scale error does not enter.
///  3. Loaded: the tips tracked at the command o; each finger's outward deflection
///         d_i = (u_i - u_i(o)) / (2 b_i)    [m]
///     and the grip force F = k (d_left + d_right) / 2 (each finger pushes with k d_i; at rest
///     they are equal). The drive's opening command stands in for the unloaded pose: the fingers'
///     own actuation is open loop and repeatable (the bender's free opening follows its command,
///     piezo_gripper.h); the stage's encoders are not used.
///
/// Noise: F averages two tips, sigma_F = k sigma_tip / sqrt(2) for independent tip noise
/// sigma_tip [m] (the goal: <= 2 k sigma_tip). Bias: whatever moves a tip's match other
/// than the deflection (a part's defocused face beside it, the unloaded line's error).
/// Not thread-safe: one per camera thread; the trackers allocate in OpenCV (not on the loop).

#include <vector>

#include "microcobot/imaging/pixel_roi.h"
#include "microcobot/vision/template_tracker.h"

namespace mc::vision {

struct FingerForceParams {
  double finger_stiffness_N_m = 50.0;  ///< k per finger (microworld gripper.finger_stiffness_N_m)
  TrackerParams tracker;

  template <class V>
  void visit(V& v) {
    v("finger_stiffness_N_m", finger_stiffness_N_m);
    v("tracker", tracker);
  }
  /// Throws mc::InvalidParams naming the field (NaN, <= 0).
  void validate() const;
};

struct FingerForceEstimate {
  double grip_force_N = 0.0;
  double deflection_left_m = 0.0, deflection_right_m = 0.0;  ///< outward, per finger
  double u_left_px = 0.0, u_right_px = 0.0;                  ///< the tips' tracked columns
  double confidence = 0.0;                                   ///< the lower of the two matches
  bool found = false;  ///< false: a tip was lost (no force: the estimate is not published)
};

class FingerForce {
 public:
  explicit FingerForce(const FingerForceParams& params = {});
  const FingerForceParams& params() const { return p_; }

  /// The tips' templates from `frame` (nothing between the fingers). Throws mc::InvalidInput
  /// naming an ROI that is empty, too small, outside the frame or without contrast.
  void set_templates(const imaging::Frame& frame, const imaging::PixelRoi& left,
                     const imaging::PixelRoi& right);
  /// One unloaded observation: the tips tracked in `frame` taken at the opening command
  /// `opening_m`. Throws InvalidInput when a tip is lost or the command is not finite.
  void add_unloaded(const imaging::Frame& frame, double opening_m);
  /// Fits the unloaded lines. Throws InvalidInput with fewer than two distinct openings, or when a
  /// tip did not move with the opening.
  void fit_unloaded();
  bool calibrated() const { return fitted_; }
  /// The unloaded lines' rms residual [px].
  double unloaded_residual_px() const { return residual_px_; }
  /// The scale along the opening, px per metre of opening, per tip (signed).
  double slope_left_px_m() const { return b_[0]; }
  double slope_right_px_m() const { return b_[1]; }

  /// The grip force in `frame` taken at the opening command `opening_m`. Throws InvalidInput
  /// before fit_unloaded() or for a non-finite command.
  FingerForceEstimate measure(const imaging::Frame& frame, double opening_m);

 private:
  FingerForceParams p_;
  TemplateTracker left_, right_;
  std::vector<double> openings_, u_left_, u_right_;
  double a_[2] = {0.0, 0.0}, b_[2] = {0.0, 0.0};
  double residual_px_ = 0.0;
  bool fitted_ = false;
};

}  // namespace mc::vision
