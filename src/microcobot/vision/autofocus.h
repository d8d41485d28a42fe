#pragma once
/// @file
/// Autofocus (docs/concepts/vision.md, "Autofocus and depth from focus"): a search for the focus
/// height that maximises a focus measure F (sharpness.h), stepped by its caller one frame at a time, as a
/// tracker or a servo task is: the search says where to set the focus (next_focus_m()), the
/// caller takes a frame there, measures its sharpness and hands it back (observe()).
///
///  1. Coarse scan on a grid of h = coarse_step_m from the start. While the measures are flat
///     (the largest under min_contrast times the smallest: far out of focus, where the image has
///     lost its texture) the scan spirals outwards, start + h, start - h, start + 2h, ...; once
///     they are not, and both start + h and start - h are measured (a slope on one side of the
///     start may be another surface's while the peak is on the other: the tool's tips from
///     above, the fingers' body rising beyond them), it climbs: a step from the sharpest sample
///     towards the side it has no
///     neighbour on, until the sharpest sample has a neighbour on either side (a bracket
///     b - h, b, b + h with F(b) the largest) or is the range's end.
///  2. Refinement, with the fine metric (fine_metric; the coarse one when empty), by successive
///     three-point fits (a coarse-to-fine parabolic interpolation, Brent, "Algorithms for
///     Minimization without Derivatives", 1973, ch. 5, with the sample spacing set instead of
///     chosen): the bracket's vertex is the first centre z_1; stage k
///     samples z_k - d_k, z_k, z_k + d_k with d_k = max(h / r^k, final_step_m) (r = refinement)
///     and its vertex is z_{k+1}. Symmetric samples make the vertex unbiased whatever the
///     peak's exact shape (the model's F is even in z - z*). When the sharpest of the three is an
///     end, the peak is beyond it: the next stage centres there with the same d (a climb).
///     The search ends after the stage with d = final_step_m, or when the frame budget is used.
///  3. Each vertex: the parabola through (z, 1/F) (peak_model "lorentzian", the default: exact
///     for the normalised variance of a fine texture, depth_from_focus.h) or (z, ln F)
///     ("gaussian"), through the three samples.
///
/// No peak: when the measures stay flat (a textureless region: noise only) over the whole range
/// or the frame budget, the search reports not converged and leaves the best focus at the start.
/// A peak at the range's end: the stages close in on the end; the parabola through the end and
/// its two nearest samples tells whether the peak is at the end (converged, the end) or beyond
/// it (not converged): a parabola that bends up (the measure rising ever faster into the end)
/// has no peak, whatever its vertex.
///
/// Allocation: the samples' storage is reserved on construction (max_frames); observe() and
/// next_focus_m() allocate nothing.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "microcobot/imaging/optics.h"
#include "microcobot/vision/depth_from_focus.h"
#include "microcobot/vision/sharpness.h"

namespace mc::vision {

/// The search's parameters (defaults and their sources: docs/parameters.md, "Autofocus"; chosen
/// on the tuning set, docs/benchmarks.md "Autofocus").
struct AutofocusParams {
  double range_min_m = -300e-6;  ///< lowest focus height the search may set
  double range_max_m = 300e-6;   ///< highest
  double start_m = 0.0;          ///< the focus height at the start (the current focus)
  double coarse_step_m = 40e-6;  ///< h: the coarse scan's step
  double refinement = 5.0;       ///< r: each stage's spacing is the previous one's / r
  double final_step_m = 4.5e-6;  ///< the last stage's spacing (half the 10x objective's depth of field)
  int max_frames = 15;           ///< frame budget (the search ends when it is used)
  /// The coarse scan's focus measure: the normalised variance keeps a slope far from focus (its
  /// coarse texture octaves), where gradient measures are flat (docs/concepts/vision.md, "Autofocus and depth
  /// from focus").
  std::string metric = "normalized-variance";
  /// The refinement's ("" = metric): a gradient measure's peak is narrower and, on edges, the
  /// one at the surface's height (the variance of a step hardly changes with focus).
  std::string fine_metric = "tenengrad";
  double min_contrast = kDefaultMinFocusContrast;  ///< largest / smallest measure for a peak
  std::string peak_model = "lorentzian";           ///< "lorentzian" (1/F) or "gaussian" (ln F)
  /// The refinement may take a coarse sample of its own metric as one of its samples (a frame
  /// saved). False when the caller measures the coarse scan on another region than the
  /// refinement (a wide region to find a small target far out of focus, the target's own to place
  /// it: the tool's tips, docs/concepts/vision.md "Autofocus and depth from focus"): next_is_coarse() tells
  /// the caller which.
  bool reuse_coarse_samples = true;

  template <class V>
  void visit(V& v) {
    v("range_min_m", range_min_m);
    v("range_max_m", range_max_m);
    v("start_m", start_m);
    v("coarse_step_m", coarse_step_m);
    v("refinement", refinement);
    v("final_step_m", final_step_m);
    v("max_frames", max_frames);
    v("metric", metric);
    v("fine_metric", fine_metric);
    v("min_contrast", min_contrast);
    v("peak_model", peak_model);
    v("reuse_coarse_samples", reuse_coarse_samples);
  }
  /// Throws InvalidParams naming the field (NaN, negative, an empty range, the start outside it...).
  void validate() const;
};

/// The last stage's spacing in depths of field (autofocus_params_for()).
inline constexpr double kFinalStepDof = 1.0;
inline constexpr double kFinalStepDofGradient = 0.5;
/// A gradient measure refines only where the in-focus PSF is sampled finely enough for pixel
/// differences to carry it: Gaussian sigma <= this many pixels (10x: 0.87, 20x: 1.16, 50x: 2.2).
inline constexpr double kGradientMaxPsfSigmaPx = 1.5;
/// The fine metric autofocus_params_for() picks: Tenengrad when the PSF's sigma is at most
/// kGradientMaxPsfSigmaPx pixels, else the normalised variance (tuning set, docs/benchmarks.md).
FocusMetric default_fine_metric(const imaging::OpticsFigures& figures);
/// The defaults for an objective, starting at `start_m` (the range widened to hold it), refined
/// with `fine_metric`: final_step_m = kFinalStepDof (normalised variance) or kFinalStepDofGradient
/// (Tenengrad, Brenner: narrower peaks) x its depth of field. The coarse step is the same for every
/// objective: far from focus the measure's slope comes from the texture's coarse octaves, not
/// from the depth of field (docs/concepts/vision.md, "Autofocus and depth from focus").
AutofocusParams autofocus_params_for(const imaging::OpticsFigures& figures, double start_m,
                                     FocusMetric fine_metric);
/// The same with default_fine_metric(figures).
AutofocusParams autofocus_params_for(const imaging::OpticsFigures& figures, double start_m);

class Autofocus {
 public:
  /// Validates `params` (throws InvalidParams).
  explicit Autofocus(const AutofocusParams& params);

  const AutofocusParams& params() const { return p_; }
  /// The focus measure the next frame is to be measured with (observe()).
  FocusMetric next_metric() const { return phase_ == Phase::kCoarse ? metric_ : fine_metric_; }
  /// The next frame is for the coarse scan (else for the refinement).
  bool next_is_coarse() const { return phase_ == Phase::kCoarse; }

  /// The search has ended (converged or not): no more frames wanted.
  bool done() const { return phase_ == Phase::kDone; }
  /// The focus height for the next frame (while !done()).
  double next_focus_m() const { return next_z_; }
  /// The focus measure next_metric() of the frame taken at next_focus_m(). Throws InvalidInput for a negative
  /// or non-finite measure, or when the search is done.
  void observe(double sharpness);

  /// A peak was found and located (once done()).
  bool converged() const { return converged_; }
  /// The estimated plane of best focus when converged; otherwise the start (no peak) or the
  /// sharpest sample (the peak beyond the range, or the budget used before a bracket).
  double best_focus_m() const { return best_z_; }
  int frames_used() const { return static_cast<int>(samples_.size()); }
  /// Why the search ended ("" while running).
  const char* status() const { return status_; }
  /// Every (height, measure) observed, in order, and the metric of each.
  std::span<const FocusSample> observations() const { return samples_; }
  std::span<const FocusMetric> observation_metrics() const { return sample_metrics_; }

 private:
  enum class Phase { kCoarse, kRefine, kDone };
  double clamp_z(double z) const;
  bool measured(double z) const;
  /// Sample i counts in the refinement: of the fine metric, and not the coarse scan's unless reused.
  bool refinement_sample(std::size_t i) const;
  double y_of(double f) const;
  void coarse_next(bool budget_used);
  void start_stage(double centre, double spacing, bool budget_used);
  void end_stage(bool budget_used);
  void finish(const char* why);

  AutofocusParams p_;
  FocusMetric metric_, fine_metric_;
  bool gaussian_ = false;
  std::vector<FocusSample> samples_;
  std::vector<FocusMetric> sample_metrics_;
  std::vector<std::uint8_t> sample_coarse_;  // taken by the coarse scan
  Phase phase_ = Phase::kCoarse;
  double next_z_ = 0.0;
  // Coarse scan: the spiral's next ring and side; the sharpest sample.
  int ring_ = 1;
  int side_ = 1;
  std::size_t best_ = 0;
  // Refinement: the stage's centre, spacing, heights to measure and the samples it took.
  double centre_ = 0.0, spacing_ = 0.0;
  double todo_[3] = {0, 0, 0};
  int n_todo_ = 0, i_todo_ = 0;
  FocusSample stage_[3];
  int n_stage_ = 0;
  // Result.
  bool converged_ = false;
  double best_z_ = 0.0;
  const char* status_ = "";
};

}  // namespace mc::vision
