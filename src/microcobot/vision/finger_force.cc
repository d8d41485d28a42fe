#include "microcobot/vision/finger_force.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "microcobot/core/error.h"

namespace mc::vision {

void FingerForceParams::validate() const {
  require(std::isfinite(finger_stiffness_N_m) && finger_stiffness_N_m > 0.0 && finger_stiffness_N_m <= 1e7,
          "finger_stiffness_N_m", "must be finite, within (0, 1e7] N/m", finger_stiffness_N_m);
  tracker.validate();
}

FingerForce::FingerForce(const FingerForceParams& params)
    : p_(params), left_(params.tracker), right_(params.tracker) {
  p_.validate();
}

void FingerForce::set_templates(const imaging::Frame& frame, const imaging::PixelRoi& left,
                                const imaging::PixelRoi& right) {
  try {
    left_.set_template(frame, left);
  } catch (const InvalidInput& e) {
    throw InvalidInput(std::string("left finger: ") + e.what());
  }
  try {
    right_.set_template(frame, right);
  } catch (const InvalidInput& e) {
    throw InvalidInput(std::string("right finger: ") + e.what());
  }
  openings_.clear();
  u_left_.clear();
  u_right_.clear();
  fitted_ = false;
}

void FingerForce::add_unloaded(const imaging::Frame& frame, double opening_m) {
  if (!std::isfinite(opening_m))
    throw InvalidInput(fmt::format("finger force: opening {} m is not finite", opening_m));
  if (!left_.has_template() || !right_.has_template())
    throw InvalidInput("finger force: no templates (set_templates first)");
  const TrackEstimate l = left_.track(frame), r = right_.track(frame);
  if (!l.found || !r.found)
    throw InvalidInput(fmt::format("finger force: the {} tip was lost at the unloaded opening {:.1f} um",
                                   l.found ? "right" : "left", opening_m * 1e6));
  openings_.push_back(opening_m);
  u_left_.push_back(l.u_px);
  u_right_.push_back(r.u_px);
  fitted_ = false;
}

void FingerForce::fit_unloaded() {
  const std::size_t n = openings_.size();
  const auto [lo, hi] = std::minmax_element(openings_.begin(), openings_.end());
  if (n < 2 || *hi - *lo <= 0.0)
    throw InvalidInput(
        fmt::format("finger force: {} unloaded opening(s); the unloaded pose needs at least two "
                    "different openings",
                    n));
  double mo = 0.0;
  for (double o : openings_) mo += o / static_cast<double>(n);
  double ss = 0.0, sq = 0.0;
  for (double o : openings_) ss += (o - mo) * (o - mo);
  const std::vector<double>* us[2] = {&u_left_, &u_right_};
  for (int t = 0; t < 2; ++t) {
    const std::vector<double>& u = *us[t];
    double mu = 0.0, so = 0.0;
    for (double x : u) mu += x / static_cast<double>(n);
    for (std::size_t k = 0; k < n; ++k) so += (openings_[k] - mo) * (u[k] - mu);
    b_[t] = so / ss;
    a_[t] = mu - b_[t] * mo;
    for (std::size_t k = 0; k < n; ++k) {
      const double r = u[k] - (a_[t] + b_[t] * openings_[k]);
      sq += r * r;
    }
    // The tip must move with the opening, outward: left to lower columns, right to higher ones.
    const double expected_sign = t == 0 ? -1.0 : 1.0;
    if (!(b_[t] * expected_sign > 0.0))
      throw InvalidInput(
          fmt::format("finger force: the {} tip did not move outward with the opening ({:.3g} px/m)",
                      t == 0 ? "left" : "right", b_[t]));
  }
  residual_px_ = std::sqrt(sq / static_cast<double>(2 * n));
  fitted_ = true;
}

FingerForceEstimate FingerForce::measure(const imaging::Frame& frame, double opening_m) {
  if (!fitted_) throw InvalidInput("finger force: no unloaded pose (fit_unloaded first)");
  if (!std::isfinite(opening_m))
    throw InvalidInput(fmt::format("finger force: opening {} m is not finite", opening_m));
  const TrackEstimate l = left_.track(frame), r = right_.track(frame);
  FingerForceEstimate e;
  e.u_left_px = l.u_px;
  e.u_right_px = r.u_px;
  e.confidence = std::min(l.confidence, r.confidence);
  e.found = l.found && r.found;
  if (!e.found) return e;
  e.deflection_left_m = (l.u_px - (a_[0] + b_[0] * opening_m)) / (2.0 * b_[0]);
  e.deflection_right_m = (r.u_px - (a_[1] + b_[1] * opening_m)) / (2.0 * b_[1]);
  e.grip_force_N = p_.finger_stiffness_N_m * 0.5 * (e.deflection_left_m + e.deflection_right_m);
  return e;
}

}  // namespace mc::vision
