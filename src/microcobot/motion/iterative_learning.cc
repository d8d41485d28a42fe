#include "microcobot/motion/iterative_learning.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "microcobot/core/error.h"

namespace mc::motion {

void LearningParams::validate() const {
  require_positive(control_rate_Hz, "learning.control_rate_Hz");
  // gamma in (0, 2): the bound of |1 - gamma| < 1 with P = 1 (iterative_learning.h).
  require(learning_gain > 0.0 && learning_gain < 2.0, "learning.learning_gain", "must lie in (0, 2)",
          learning_gain);
  require(lead_ticks >= 0 && lead_ticks <= 100, "learning.lead_ticks", "must lie in [0, 100]",
          static_cast<double>(lead_ticks));
  require(q_cutoff_Hz == 0.0 || (q_cutoff_Hz > 0.0 && q_cutoff_Hz < 0.5 * control_rate_Hz),
          "learning.q_cutoff_Hz", "must be 0 (off) or lie in (0, control_rate_Hz / 2)", q_cutoff_Hz);
  require(forgetting >= 0.0 && forgetting < 1.0, "learning.forgetting", "must lie in [0, 1)", forgetting);
  require_positive(max_correction_m, "learning.max_correction_m");
}

void ReferenceHash::add(double x_m) noexcept {
  // 1 pm quantum: the same reference computed the same way gives the same identity, while any
  // change a controller could notice changes it.
  const double q = std::isfinite(x_m) ? std::round(x_m * 1e12) : 0.0;
  add_id(static_cast<std::uint64_t>(static_cast<std::int64_t>(std::clamp(q, -9e18, 9e18))));
}

void ReferenceHash::add_id(std::uint64_t id) noexcept {
  for (int b = 0; b < 8; ++b) {
    h_ ^= (id >> (8 * b)) & 0xffU;
    h_ *= 1099511628211ULL;
  }
}

IterativeLearning::IterativeLearning(const LearningParams& p, long max_ticks)
    : p_((p.validate(), p)),
      q_pole_(p.q_cutoff_Hz > 0.0 ? std::exp(-2.0 * std::numbers::pi * p.q_cutoff_Hz / p.control_rate_Hz)
                                  : 0.0) {
  require(max_ticks >= 1 && max_ticks <= 100'000'000, "max_ticks", "must lie in [1, 1e8]",
          static_cast<double>(max_ticks));
  u_.assign(static_cast<std::size_t>(max_ticks), 0.0);
  e_.assign(static_cast<std::size_t>(max_ticks), 0.0);
}

void IterativeLearning::reset() noexcept {
  std::fill(u_.begin(), u_.end(), 0.0);
  std::fill(e_.begin(), e_.end(), 0.0);
  learned_ticks_ = recorded_ticks_ = dropped_ = 0;
  trials_ = 0;
  has_id_ = false;
}

void IterativeLearning::begin_trial(std::uint64_t id) noexcept {
  if (has_id_ && id != id_) reset();
  id_ = id;
  has_id_ = true;
  recorded_ticks_ = dropped_ = 0;
}

void IterativeLearning::record(long i, double error_m) noexcept {
  if (i < 0) return;
  if (i >= max_ticks()) {
    ++dropped_;
    return;
  }
  // A non-finite measurement teaches nothing: it counts as no error.
  e_[static_cast<std::size_t>(i)] = std::isfinite(error_m) ? error_m : 0.0;
  recorded_ticks_ = std::max(recorded_ticks_, i + 1);
}

void IterativeLearning::learn() noexcept {
  const long n = recorded_ticks_;
  if (n == 0) return;
  const auto un = static_cast<std::size_t>(n);
  // u - gamma e(i + lambda); past the trial's end the last error stands (the reference rests there).
  for (std::size_t i = 0; i < un; ++i) {
    const std::size_t j = std::min(un - 1, i + static_cast<std::size_t>(p_.lead_ticks));
    u_[i] -= p_.learning_gain * e_[j];
  }
  // Beyond the trial, a correction learned on a longer trial is dropped.
  std::fill(u_.begin() + static_cast<std::ptrdiff_t>(un), u_.end(), 0.0);
  if (q_pole_ > 0.0) {
    // Q: forward then backward (zero phase), each started on its first sample (no start transient).
    const double a = q_pole_, b = 1.0 - q_pole_;
    double y = u_[0];
    for (std::size_t i = 0; i < un; ++i) u_[i] = y = a * y + b * u_[i];
    y = u_[un - 1];
    for (std::size_t i = un; i-- > 0;) u_[i] = y = a * y + b * u_[i];
  }
  const double keep = 1.0 - p_.forgetting;
  for (std::size_t i = 0; i < un; ++i)
    u_[i] = std::clamp(keep * u_[i], -p_.max_correction_m, p_.max_correction_m);
  learned_ticks_ = n;
  ++trials_;
}

}  // namespace mc::motion
