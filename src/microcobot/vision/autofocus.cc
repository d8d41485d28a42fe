#include "microcobot/vision/autofocus.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"

namespace mc::vision {

namespace {
constexpr const char* kFlat = "no peak: the focus measure is flat (a textureless region?)";
}

void AutofocusParams::validate() const {
  require(std::isfinite(range_min_m), "range_min_m", "must be finite", range_min_m);
  require(std::isfinite(range_max_m) && range_max_m > range_min_m, "range_max_m",
          "must be finite and > range_min_m", range_max_m);
  require(std::isfinite(start_m) && start_m >= range_min_m && start_m <= range_max_m, "start_m",
          "must be within [range_min_m, range_max_m]", start_m);
  require(std::isfinite(coarse_step_m) && coarse_step_m > 0.0, "coarse_step_m", "must be finite and > 0",
          coarse_step_m);
  require(std::isfinite(refinement) && refinement > 1.0 && refinement <= 100.0, "refinement",
          "must be within (1, 100]", refinement);
  require(std::isfinite(final_step_m) && final_step_m > 0.0 && final_step_m <= coarse_step_m, "final_step_m",
          "must be within (0, coarse_step_m]", final_step_m);
  require(max_frames >= 3 && max_frames <= 10000, "max_frames", "must be within [3, 10000]", max_frames);
  SharpnessParams{metric, 0.0}.validate();
  if (!fine_metric.empty()) {
    SharpnessParams fine{fine_metric, 0.0};
    try {
      fine.validate();
    } catch (const InvalidParams&) {
      throw InvalidParams("fine_metric", "must be empty, normalized-variance, tenengrad or brenner, not '" +
                                             excerpt(fine_metric) + "'");
    }
  }
  require(std::isfinite(min_contrast) && min_contrast >= 1.0, "min_contrast", "must be finite and >= 1",
          min_contrast);
  require(peak_model == "lorentzian" || peak_model == "gaussian", "peak_model",
          "must be lorentzian or gaussian, not '" + excerpt(peak_model) + "'");
}

FocusMetric default_fine_metric(const imaging::OpticsFigures& figures) {
  const double sigma_px = figures.psf_sigma_m / (figures.um_per_px * 1e-6);
  return sigma_px <= kGradientMaxPsfSigmaPx ? FocusMetric::kTenengrad : FocusMetric::kNormalizedVariance;
}

AutofocusParams autofocus_params_for(const imaging::OpticsFigures& figures, double start_m) {
  return autofocus_params_for(figures, start_m, default_fine_metric(figures));
}

AutofocusParams autofocus_params_for(const imaging::OpticsFigures& figures, double start_m,
                                     FocusMetric fine_metric) {
  AutofocusParams p;
  p.fine_metric = focus_metric_name(fine_metric);
  p.start_m = start_m;
  p.range_min_m = std::min(p.range_min_m, start_m);
  p.range_max_m = std::max(p.range_max_m, start_m);
  const double dofs = fine_metric == FocusMetric::kNormalizedVariance ? kFinalStepDof : kFinalStepDofGradient;
  p.final_step_m = std::min(dofs * figures.dof_m, p.coarse_step_m);
  return p;
}

Autofocus::Autofocus(const AutofocusParams& params) : p_(params) {
  p_.validate();
  metric_ = parse_focus_metric(p_.metric);
  fine_metric_ = p_.fine_metric.empty() ? metric_ : parse_focus_metric(p_.fine_metric);
  gaussian_ = p_.peak_model == "gaussian";
  samples_.reserve(static_cast<std::size_t>(p_.max_frames));
  sample_metrics_.reserve(static_cast<std::size_t>(p_.max_frames));
  sample_coarse_.reserve(static_cast<std::size_t>(p_.max_frames));
  next_z_ = p_.start_m;
  best_z_ = p_.start_m;
}

double Autofocus::clamp_z(double z) const { return std::clamp(z, p_.range_min_m, p_.range_max_m); }

bool Autofocus::measured(double z) const {
  for (const FocusSample& s : samples_)
    if (std::abs(s.z_m - z) <= 1e-3 * p_.final_step_m) return true;
  return false;
}

bool Autofocus::refinement_sample(std::size_t i) const {
  return sample_metrics_[i] == fine_metric_ && (p_.reuse_coarse_samples || !sample_coarse_[i]);
}

double Autofocus::y_of(double f) const {
  const double g = std::max(f, 1e-300);
  return gaussian_ ? std::log(g) : -1.0 / g;
}

void Autofocus::observe(double sharpness) {
  if (phase_ == Phase::kDone) throw InvalidInput("autofocus: observe() after the search ended");
  if (!std::isfinite(sharpness) || sharpness < 0.0)
    throw InvalidInput("autofocus: focus measure " + std::to_string(sharpness) +
                       " (expected a finite value >= 0)");
  samples_.push_back({next_z_, sharpness});
  sample_metrics_.push_back(next_metric());
  sample_coarse_.push_back(next_is_coarse() ? 1 : 0);
  const bool budget_used = static_cast<int>(samples_.size()) >= p_.max_frames;
  if (phase_ == Phase::kCoarse) {
    if (sharpness > samples_[best_].sharpness) best_ = samples_.size() - 1;
    coarse_next(budget_used);
    return;
  }
  stage_[n_stage_++] = samples_.back();
  if (++i_todo_ < n_todo_) {
    if (budget_used)
      finish("frame budget used");
    else
      next_z_ = todo_[i_todo_];
    return;
  }
  end_stage(budget_used);
}

void Autofocus::coarse_next(bool budget_used) {
  double lo = samples_[0].sharpness, hi = lo;
  for (const FocusSample& s : samples_) lo = std::min(lo, s.sharpness), hi = std::max(hi, s.sharpness);
  const double h = p_.coarse_step_m;
  const double first = std::max(h / p_.refinement, p_.final_step_m);
  const bool contrast = hi > 0.0 && hi >= p_.min_contrast * lo;
  if (contrast && ring_ == 1 && side_ < 0) {
    // Both sides of the start before the first climb: a slope on one side may be the tail of
    // something else while the peak is on the other (the tool's tips from 100 um above: the
    // fingers' body, rising beyond them, sharpens upwards from a minimum near the start).
    ++ring_;
    side_ = 1;
    const double down = p_.start_m - h;
    if (down >= p_.range_min_m && !measured(down)) {
      if (budget_used) {
        finish("frame budget used");
      } else {
        next_z_ = down;
      }
      return;
    }
  }
  if (contrast) {
    // Climb: the sharpest sample's nearest neighbours below and above.
    const FocusSample b = samples_[best_];
    const FocusSample* below = nullptr;
    const FocusSample* above = nullptr;
    for (const FocusSample& s : samples_) {
      if (s.z_m < b.z_m && (!below || s.z_m > below->z_m)) below = &s;
      if (s.z_m > b.z_m && (!above || s.z_m < above->z_m)) above = &s;
    }
    if (below && above) {
      const double v = parabola_vertex(below->z_m, y_of(below->sharpness), b.z_m, y_of(b.sharpness),
                                       above->z_m, y_of(above->sharpness));
      phase_ = Phase::kRefine;
      start_stage(std::clamp(v, below->z_m, above->z_m), first, budget_used);
      return;
    }
    const double zn = clamp_z(below ? b.z_m + h : b.z_m - h);
    if (zn == b.z_m) {
      // The range's end is the sharpest so far: close in on it.
      phase_ = Phase::kRefine;
      start_stage(b.z_m, first, budget_used);
    } else if (budget_used) {
      finish("frame budget used");
    } else {
      next_z_ = zn;
    }
    return;
  }
  if (budget_used) {
    finish("frame budget used");
    return;
  }
  // Flat so far: the next point of the spiral inside the range.
  for (;;) {
    const double up = p_.start_m + ring_ * h, down = p_.start_m - ring_ * h;
    if (up > p_.range_max_m && down < p_.range_min_m) {
      finish(kFlat);
      return;
    }
    const double z = side_ > 0 ? up : down;
    if (side_ < 0) ++ring_;
    side_ = -side_;
    if (z >= p_.range_min_m && z <= p_.range_max_m && !measured(z)) {
      next_z_ = z;
      return;
    }
  }
}

void Autofocus::start_stage(double centre, double spacing, bool budget_used) {
  centre_ = clamp_z(centre);
  spacing_ = spacing;
  n_todo_ = i_todo_ = n_stage_ = 0;
  double previous = std::numeric_limits<double>::quiet_NaN();
  for (double z : {centre_ - spacing, centre_, centre_ + spacing}) {
    z = clamp_z(z);
    if (z == previous) continue;  // clamped onto the range's end twice
    previous = z;
    const FocusSample* seen = nullptr;  // a sample of the fine metric there
    for (std::size_t i = 0; i < samples_.size(); ++i)
      if (refinement_sample(i) && std::abs(samples_[i].z_m - z) <= 1e-3 * p_.final_step_m)
        seen = &samples_[i];
    if (seen)
      stage_[n_stage_++] = *seen;  // measured already: no frame
    else
      todo_[n_todo_++] = z;
  }
  if (n_todo_ == 0) {
    end_stage(budget_used);
  } else if (budget_used) {
    finish("frame budget used");
  } else {
    next_z_ = todo_[0];
  }
}

void Autofocus::end_stage(bool budget_used) {
  std::sort(stage_, stage_ + n_stage_,
            [](const FocusSample& a, const FocusSample& b) { return a.z_m < b.z_m; });
  int b = 0;
  for (int i = 1; i < n_stage_; ++i)
    if (stage_[i].sharpness > stage_[b].sharpness) b = i;
  const bool last = spacing_ <= p_.final_step_m * (1.0 + 1e-9);
  const double next_spacing = std::max(spacing_ / p_.refinement, p_.final_step_m);
  if (n_stage_ == 3 && b == 1) {
    const double v =
        std::clamp(parabola_vertex(stage_[0].z_m, y_of(stage_[0].sharpness), stage_[1].z_m,
                                   y_of(stage_[1].sharpness), stage_[2].z_m, y_of(stage_[2].sharpness)),
                   stage_[0].z_m, stage_[2].z_m);
    centre_ = v;
    if (last) {
      finish("converged");
    } else if (budget_used) {
      finish("frame budget used");
    } else {
      start_stage(v, next_spacing, false);
    }
    return;
  }
  // The sharpest is an end of the stage: at the range's end close in on it, else climb there.
  const double z_end = stage_[b].z_m;
  const bool range_end = z_end <= p_.range_min_m || z_end >= p_.range_max_m;
  centre_ = z_end;
  if (range_end && last) {
    finish("converged");
  } else if (budget_used) {
    finish("frame budget used");
  } else {
    start_stage(z_end, range_end ? next_spacing : spacing_, false);
  }
}

void Autofocus::finish(const char* why) {
  const bool refined = phase_ == Phase::kRefine;
  phase_ = Phase::kDone;
  status_ = why;
  converged_ = false;
  best_z_ = p_.start_m;
  if (!refined) {
    // The coarse scan found no bracket: flat (no peak), or the budget ran out on the way.
    double lo = samples_[0].sharpness, hi = lo;
    for (const FocusSample& s : samples_) lo = std::min(lo, s.sharpness), hi = std::max(hi, s.sharpness);
    if (!(hi > 0.0 && hi >= p_.min_contrast * lo))
      status_ = kFlat;
    else
      best_z_ = samples_[best_].z_m;
    return;
  }
  // The sharpest sample of the fine metric, and its two nearest.
  const FocusSample* b = nullptr;
  for (std::size_t i = 0; i < samples_.size(); ++i)
    if (refinement_sample(i) && (!b || samples_[i].sharpness > b->sharpness)) b = &samples_[i];
  const bool at_max = b && b->z_m >= p_.range_max_m, at_min = b && b->z_m <= p_.range_min_m;
  if (!at_max && !at_min) {
    converged_ = true;
    best_z_ = centre_;
    return;
  }
  // The sharpest sample is the range's end: the parabola through it and its two nearest samples
  // says whether the peak is there or beyond.
  const FocusSample* n1 = nullptr;
  const FocusSample* n2 = nullptr;
  for (std::size_t i = 0; i < samples_.size(); ++i) {
    const FocusSample& s = samples_[i];
    if (!refinement_sample(i) || &s == b) continue;
    const double d = std::abs(s.z_m - b->z_m);
    if (!n1 || d < std::abs(n1->z_m - b->z_m)) {
      n2 = n1;
      n1 = &s;
    } else if (!n2 || d < std::abs(n2->z_m - b->z_m)) {
      n2 = &s;
    }
  }
  best_z_ = b->z_m;
  if (!n2) {
    status_ = "the peak is at or beyond the range's end";
    return;
  }
  const double v =
      parabola_vertex(n2->z_m, y_of(n2->sharpness), n1->z_m, y_of(n1->sharpness), b->z_m, y_of(b->sharpness));
  const double slack = std::max(std::abs(n1->z_m - b->z_m), p_.final_step_m);
  // A vertex is a peak only where the parabola bends down (its second divided difference < 0): a
  // measure rising ever faster into the end has its parabola's vertex, a minimum, inside.
  const auto slope = [this](const FocusSample& a, const FocusSample& c) {
    return (y_of(c.sharpness) - y_of(a.sharpness)) / (c.z_m - a.z_m);
  };
  const bool bends_down = (slope(*n1, *b) - slope(*n2, *n1)) / (b->z_m - n2->z_m) < 0.0;
  if (std::isfinite(v) && bends_down && (at_max ? v <= b->z_m + slack : v >= b->z_m - slack)) {
    converged_ = true;
    best_z_ = clamp_z(v);
    status_ = "converged: the peak at the range's end";
  } else {
    status_ = "no peak inside the range: the measure rises to the range's end";
  }
}

}  // namespace mc::vision
