// Tracking that generalises: the seeded tuning and validation sets, and the
// tracking controller judged on the validation set (never tuned on it).
#include <algorithm>
#include <cstdio>
#include <set>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/core/rng.h"
#include "microcobot/studies/validation_set.h"
#include "motion/control_fixture.h"

namespace mc::studies {
namespace {

bool same(const ValidationCase& a, const ValidationCase& b) {
  return a.profile == b.profile && a.power_up == b.power_up && a.sign == b.sign &&
         a.distance_m == b.distance_m && a.velocity_m_s == b.velocity_m_s && a.amplitude_m == b.amplitude_m &&
         a.frequency_Hz == b.frequency_Hz && a.radius_m == b.radius_m && a.sensor_seed == b.sensor_seed;
}

TEST(ValidationSet, IsSeededCoversTheEnvelopeAndIsKeptApartFromTheTuningSet) {
  const auto v = make_case_set(CaseSet::kValidation, kValidationSeed, kValidationCases);
  const auto again = make_case_set(CaseSet::kValidation, kValidationSeed, kValidationCases);
  const auto other = make_case_set(CaseSet::kValidation, kValidationSeed + 1, kValidationCases);
  const auto t = make_case_set(CaseSet::kTuning, kTuningSeed, kTuningRandomCases);
  ASSERT_GE(v.size(), 30u);
  ASSERT_EQ(v.size(), again.size());
  std::set<CaseProfile> kinds;
  int power_up = 0, backward = 0, differ = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    EXPECT_TRUE(same(v[i], again[i]));  // deterministic in the seed
    differ += same(v[i], other[i]) ? 0 : 1;
    for (const auto& tc : t) EXPECT_FALSE(same(v[i], tc)) << v[i].name << " is also a tuning case";
    kinds.insert(v[i].profile);
    power_up += v[i].power_up ? 1 : 0;
    backward += v[i].sign < 0.0 ? 1 : 0;
    const auto& c = v[i];
    if (c.profile == CaseProfile::kTrapezoid || c.profile == CaseProfile::kLine) {
      EXPECT_GE(c.distance_m, 10e-6);
      EXPECT_LE(c.distance_m, 2e-3);
    }
    if (c.profile != CaseProfile::kSine) {
      EXPECT_GE(c.velocity_m_s, 20e-6);
      EXPECT_LE(c.velocity_m_s, 800e-6);
      EXPECT_GE(c.acceleration_m_s2, 2e-3);
      EXPECT_LE(c.acceleration_m_s2, 0.1);
    } else {
      EXPECT_GE(c.frequency_Hz, 0.1);
      EXPECT_LE(c.frequency_Hz, 5.0);
      EXPECT_GE(c.amplitude_m, 2e-6);
      EXPECT_LE(c.amplitude_m, 50e-6);
    }
  }
  EXPECT_EQ(kinds.size(), 4u);  // trapezoids, sines, lines, arcs
  EXPECT_GT(power_up, 5);
  EXPECT_LT(power_up, static_cast<int>(v.size()) - 5);
  EXPECT_GT(backward, 5);
  EXPECT_GT(differ, static_cast<int>(v.size()) / 2);
  // The validation set cannot be drawn with the tuning seed.
  EXPECT_THROW(make_case_set(CaseSet::kValidation, kTuningSeed, 4), InvalidParams);
  EXPECT_EQ(parse_case_set("tuning"), CaseSet::kTuning);
  EXPECT_THROW(parse_case_set("all"), InvalidParams);
}

TEST(ValidationSet, TheSeededSetIsTheSameWhateverTheCompiler) {
  // A call's arguments are evaluated in an unspecified order: GCC right to left, clang left to
  // right. Three draws in one Vector3d(...) made clang's validation set another set (the sanitizer
  // build, clang, failed the power-up goal on cases the docs never measured). These are the
  // cases GCC drew, on which docs/benchmarks.md's figures were measured.
  const auto v = make_case_set(CaseSet::kValidation, kValidationSeed, kValidationCases);
  EXPECT_EQ(
      describe(v[0]),
      "trapezoid forward 4.74e-05 m, <= 4.15e-05 m/s, <= 0.00608 m/s^2, from rest (lead-in -3.39e-05 m)");
  EXPECT_EQ(describe(v[2]), "sine backward 4.02e-06 m at 1.77 Hz (0.566 s), from power-up");
  EXPECT_EQ(describe(v[3]),
            "line 2.24e-05 m along (-0.63, 0.71, -0.32), <= 0.000278 m/s, <= 0.00913 m/s^2, from rest "
            "(lead-in 1.16e-05 m)");
  EXPECT_EQ(describe(v[7]), "arc R 2.4e-05 m, 1.9 rad, <= 0.000121 m/s, <= 0.0799 m/s^2, from power-up");
}

TEST(ValidationSet, ThePowerUpBackwardGoalIsJudgedOnlyWhereItApplies) {
  ValidationCase c;
  c.sign = -1.0;
  EXPECT_TRUE(starts_backward_from_power_up(c));
  c.power_up = false;
  EXPECT_FALSE(starts_backward_from_power_up(c));
  c.power_up = true;
  c.profile = CaseProfile::kLine;
  EXPECT_FALSE(starts_backward_from_power_up(c));
}

// The tracking goals on a reduced random subset of the validation set (12 of its 32 cases, chosen
// by a seeded shuffle; the full table is `microcobot control validate`, docs/benchmarks.md). The
// controller was tuned on the tuning set only. Goals that hold on the full validation set are
// asserted as goals; those that do not (docs/benchmarks.md names the cases) are asserted at the
// level measured, so that a regression fails.
TEST(ValidationSet, AReducedRandomValidationSubsetMeetsTheTrackingGoals) {
  const auto all = make_case_set(CaseSet::kValidation, kValidationSeed, kValidationCases);
  std::vector<std::size_t> idx(all.size());
  for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = i;
  Rng rng(20261125);
  for (std::size_t i = idx.size() - 1; i > 0; --i) std::swap(idx[i], idx[rng.next_u64() % (i + 1)]);
  idx.resize(12);
  std::vector<ValidationCase> cases;
  std::vector<CaseResult> results;
  const TrackerSetup su;
  const TrackingGoals goals;
  for (std::size_t i : idx) {
    cases.push_back(all[i]);
    results.push_back(run_case(motion::test::model(), motion::test::step_map(), su, all[i], goals));
    SCOPED_TRACE(all[i].name + ": " + describe(all[i]));
    if (all[i].profile != CaseProfile::kSine) {
      EXPECT_LE(results.back().final_m, 5e-9);  // at rest: the final-error goal
    }
  }
  const ValidationSummary s = summarise(cases, results, goals);
  std::printf(
      "subset: %d/%d pass, median RMS %.1f nm, worst RMS %.0f, max %.0f, path %.0f, power-up backward %.0f "
      "nm\n",
      s.passed, s.cases, s.median_rms_m * 1e9, s.worst_rms_m * 1e9, s.worst_max_m * 1e9,
      s.worst_path_deviation_m * 1e9, s.worst_powerup_backward_m * 1e9);
  // Hold on the full validation set (median 99 nm, power-up backward 208 nm, with the
  // lead on the plan and resonant damping): the goals themselves.
  EXPECT_TRUE(s.median_ok) << s.median_rms_m;
  EXPECT_TRUE(s.powerup_ok) << s.worst_powerup_backward_m;
  // Do not hold on the full validation set (worst RMS 219 nm, max 642 nm, path deviation 382 nm:
  // docs/benchmarks.md); bounded at the measured level with
  // ~10 % margin, so that a regression fails.
  EXPECT_LE(s.worst_rms_m, 240e-9);
  EXPECT_LE(s.worst_max_m, 700e-9);
  EXPECT_LE(s.worst_path_deviation_m, 420e-9);
}

}  // namespace
}  // namespace mc::studies
