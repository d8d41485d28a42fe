#include "microcobot/studies/learning_run.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::studies {

namespace {
constexpr double kTick_s = 1e-4;  // the 10 kHz control tick of run_tracker()
}  // namespace

std::uint64_t case_identity(const ValidationCase& c, std::uint64_t axis_id) {
  double start = 0, duration = 0, from = 0;
  const ReferenceFn ref = one_d_reference(c, start, duration, from);
  motion::ReferenceHash h;
  h.add_id(axis_id);
  h.add(start);
  const long n = std::lround(duration / kTick_s);
  for (long k = 0; k < n; ++k) h.add(ref(static_cast<double>(k) * kTick_s, kTick_s).x_m);
  return h.value();
}

long case_ticks(const ValidationCase& c) {
  double start = 0, duration = 0, from = 0;
  (void)one_d_reference(c, start, duration, from);
  return std::lround(duration / kTick_s) + 1;
}

std::vector<LearningTrial> run_learning(const stickslip::ActuatorModel& model, const motion::StepMap& map,
                                        const TrackerSetup& setup, const ValidationCase& c,
                                        motion::IterativeLearning& ilc, int trials, int first_trial,
                                        bool learn, std::uint64_t axis_id) {
  require(trials >= 1 && trials <= 1000, "trials", "must lie in [1, 1000]", trials);
  require(first_trial >= 0, "first_trial", "must be >= 0", first_trial);
  require(case_ticks(c) <= ilc.max_ticks(), "learning", "the reference is longer than the learner's buffers",
          static_cast<double>(case_ticks(c)));
  const std::uint64_t id = case_identity(c, axis_id);
  std::vector<LearningTrial> out;
  std::vector<double> previous;  // the previous trial's measured errors
  for (int t = 0; t < trials; ++t) {
    TrackerSetup su = setup;
    su.sensor.seed = c.sensor_seed + 1000 * (first_trial + t);
    double start = 0, duration = 0, from = 0;
    const ReferenceFn ref = one_d_reference(c, start, duration, from);
    ilc.begin_trial(id);
    LearningTrial lt;
    lt.trial = first_trial + t;
    for (long i = 0; i < ilc.learned_ticks(); ++i)
      lt.correction_max_m = std::max(lt.correction_max_m, std::abs(ilc.feedforward(i)));
    const TrackingRecord rec =
        run_tracker(model, map, TrackerKind::kTracking, su, start, ref, duration, 100, from, &ilc);
    const auto n = static_cast<std::size_t>(ilc.recorded_ticks());
    if (t > 0 && n > 0) {
      double sq = 0.0;
      const std::size_t m = std::min(n, previous.size());
      for (std::size_t i = 0; i < m; ++i) sq += std::pow(ilc.errors()[i] - previous[i], 2);
      lt.change_rms_m = m > 0 ? std::sqrt(sq / static_cast<double>(m)) : 0.0;
    }
    previous.assign(ilc.errors().begin(), ilc.errors().begin() + static_cast<std::ptrdiff_t>(n));
    if (learn) ilc.learn();
    lt.rms_m = rec.metrics.rms_error_m;
    lt.max_m = rec.metrics.max_error_m;
    lt.final_m = rec.metrics.final_error_m;
    out.push_back(lt);
  }
  return out;
}

}  // namespace mc::studies
