// Iterative learning on repeated references of the validation set (studies/learning_run.h): the
// law's defaults were chosen on the tuning set (seed 15) and are judged here on the validation
// set's draw (seed 31).
#include <algorithm>
#include <cstdio>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/motion/control_params.h"
#include "microcobot/studies/learning_run.h"
#include "motion/control_fixture.h"

namespace mc::studies {
namespace {

/// Trial-to-trial scatter of a case's RMS with no learning at all, measured on the tuning set's 1-D
/// cases (`microcobot control learn --set tuning --references 30 --trials 11 --gain 1e-9`): up to
/// +12.8 %. The edges' dips are not repeatable in time, so "no worse than the first" holds up to it.
constexpr double kLearningScatter = 1.15;

std::vector<ValidationCase> validation_one_d(int n) {
  std::vector<ValidationCase> out;
  for (const auto& c : make_case_set(CaseSet::kValidation, kValidationSeed, kValidationCases))
    if (is_one_d(c) && static_cast<int>(out.size()) < n) out.push_back(c);
  return out;
}

const TrackerSetup& learning_setup() {
  static const TrackerSetup su = tracker_setup(motion::ControlParams{});
  return su;
}

TEST(LearningRun, OnValidationReferencesTheRmsFallsOverTrials) {
  double first = 0.0, last = 0.0;
  for (const auto& c : validation_one_d(3)) {
    motion::IterativeLearning ilc(motion::LearningParams{}, case_ticks(c));
    const auto t =
        run_learning(motion::test::model(), motion::test::step_map(), learning_setup(), c, ilc, 11);
    ASSERT_EQ(t.size(), 11u);
    const double tail = (t[8].rms_m + t[9].rms_m + t[10].rms_m) / 3.0;
    std::printf("%s: RMS %.1f nm -> %.1f nm (mean of trials 8-10), max %.0f -> %.0f nm\n", c.name.c_str(),
                t[0].rms_m * 1e9, tail * 1e9, t[0].max_m * 1e9, t[10].max_m * 1e9);
    for (const auto& x : t)
      EXPECT_LE(x.rms_m, kLearningScatter * t[0].rms_m) << c.name << " trial " << x.trial;
    first += t[0].rms_m;
    last += tail;
    EXPECT_EQ(ilc.trials(), 11);
    EXPECT_GT(t[10].correction_max_m, 0.0);
  }
  EXPECT_LT(last, first);
}

TEST(LearningRun, FrictionChangedByTenPercentAfterLearningDoesNotDiverge) {
  const ValidationCase c = validation_one_d(1).front();
  motion::IterativeLearning learned(motion::LearningParams{}, case_ticks(c));
  run_learning(motion::test::model(), motion::test::step_map(), learning_setup(), c, learned, 6);
  for (double scale : {0.9, 1.1}) {
    // The contact's force per strain and per strain rate (both asperities) scaled: the friction the
    // correction was learned on, changed; the controller's step map stays the nominal one.
    stickslip::StickSlipParams changed = motion::test::model().params();
    changed.friction.rho0_a_N_m *= scale;
    changed.friction.rho1_a_N_s_m *= scale;
    changed.friction.rho0_b_N_m *= scale;
    changed.friction.rho1_b_N_s_m *= scale;
    const stickslip::ActuatorModel axis(changed, motion::test::model().dt_s());
    motion::IterativeLearning fresh(motion::LearningParams{}, case_ticks(c));
    const double first =
        run_learning(axis, motion::test::step_map(), learning_setup(), c, fresh, 1, 0, false).front().rms_m;
    motion::IterativeLearning ilc = learned;  // the correction learned on the nominal axis, kept on
    const auto t = run_learning(axis, motion::test::step_map(), learning_setup(), c, ilc, 6, 6);
    for (const auto& x : t) {
      std::printf("friction x%.1f trial %d: RMS %.1f nm (first, no correction: %.1f nm), max %.0f nm\n",
                  scale, x.trial, x.rms_m * 1e9, first * 1e9, x.max_m * 1e9);
      EXPECT_LE(x.rms_m, kLearningScatter * first) << "friction x" << scale << " trial " << x.trial;
    }
  }
}

TEST(LearningRun, ANewReferenceStartsFromNoCorrection) {
  const auto cases = validation_one_d(2);
  long ticks = std::max(case_ticks(cases[0]), case_ticks(cases[1]));
  motion::IterativeLearning ilc(motion::LearningParams{}, ticks);
  run_learning(motion::test::model(), motion::test::step_map(), learning_setup(), cases[0], ilc, 3);
  EXPECT_EQ(ilc.trials(), 3);
  EXPECT_NE(case_identity(cases[0]), case_identity(cases[1]));
  EXPECT_NE(case_identity(cases[0]), case_identity(cases[0], 1));  // another axis
  // The second reference's first trial is the one a fresh learner runs: nothing carried over.
  const auto b =
      run_learning(motion::test::model(), motion::test::step_map(), learning_setup(), cases[1], ilc, 1);
  motion::IterativeLearning fresh(motion::LearningParams{}, ticks);
  const auto f =
      run_learning(motion::test::model(), motion::test::step_map(), learning_setup(), cases[1], fresh, 1);
  EXPECT_EQ(b.front().correction_max_m, 0.0);
  EXPECT_EQ(b.front().rms_m, f.front().rms_m);
  EXPECT_EQ(ilc.trials(), 1);
  // A 3-D case is refused; so is a reference longer than the buffers.
  const auto all = make_case_set(CaseSet::kValidation, kValidationSeed, kValidationCases);
  const auto three_d = std::find_if(all.begin(), all.end(), [](const auto& x) { return !is_one_d(x); });
  ASSERT_NE(three_d, all.end());
  EXPECT_THROW(
      run_learning(motion::test::model(), motion::test::step_map(), learning_setup(), *three_d, ilc, 1),
      InvalidParams);
  motion::IterativeLearning small(motion::LearningParams{}, 10);
  EXPECT_THROW(
      run_learning(motion::test::model(), motion::test::step_map(), learning_setup(), cases[0], small, 1),
      InvalidParams);
}

}  // namespace
}  // namespace mc::studies
