// Autofocus: the goal (from 100 um out of focus, within 15 frames, the focus
// error under a fifth of the depth of field and 0.3 um at 10x) on rendered frames with the
// sensor's noise; a textureless region, the peak at the range's end or beyond it, dim (noisier)
// frames; the parameters' and the inputs' validation.

#include "microcobot/vision/autofocus.h"

#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "focus_scenes.h"
#include "microcobot/core/error.h"

namespace mc::vision {
namespace {

using testing::FocusCamera;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Runs the search on `cam`, each frame measured with the metric the search asks for.
Autofocus run(FocusCamera& cam, const AutofocusParams& p, const imaging::PixelRoi& roi = testing::kFocusRoi) {
  Autofocus af(p);
  while (!af.done()) af.observe(cam.measure(af.next_focus_m(), af.next_metric(), roi));
  return af;
}

double goal_tolerance(const imaging::OpticsFigures& f) { return std::min(0.2 * f.dof_m, 0.3e-6); }

void expect_goal(FocusCamera& cam, double z_true, double offset, const char* what) {
  const AutofocusParams p = autofocus_params_for(cam.figures(), z_true + offset);
  const Autofocus af = run(cam, p);
  const double err = af.best_focus_m() - z_true;
  std::printf("%s from %+.0f um: error %+.3f um (%.4f DOF), %d frames, %s\n", what, offset * 1e6, err * 1e6,
              err / cam.figures().dof_m, af.frames_used(), af.status());
  EXPECT_TRUE(af.converged()) << what << ": " << af.status();
  EXPECT_LE(af.frames_used(), 15) << what;
  EXPECT_LE(std::abs(err), goal_tolerance(cam.figures())) << what << " from " << offset * 1e6 << " um";
}

TEST(Autofocus, MeetsTheGoalOnATexturedSubstrateAt10x) {
  for (const double offset : {100e-6, -100e-6}) {
    FocusCamera cam("10x", testing::substrate_scene(11), 41);
    expect_goal(cam, 0.0, offset, "10x substrate");
  }
}

TEST(Autofocus, MeetsTheGoalOnAPartsTopAt10x) {
  const double z_top = 240e-6;
  for (const double offset : {100e-6, -100e-6}) {
    FocusCamera cam("10x", testing::part_scene(12, z_top), 42);
    expect_goal(cam, z_top, offset, "10x part top");
  }
}

// The other objectives, held to a fifth of their depth of field.
TEST(Autofocus, FindsTheSubstrateWithEveryObjective) {
  for (const char* objective : {"5x", "20x", "50x"}) {
    FocusCamera cam(objective, testing::substrate_scene(13), 43);
    const Autofocus af = run(cam, autofocus_params_for(cam.figures(), -100e-6));
    const double dof = cam.figures().dof_m;
    std::printf("%s substrate from -100 um: error %+.3f um (%.4f DOF), %d frames\n", objective,
                af.best_focus_m() * 1e6, af.best_focus_m() / dof, af.frames_used());
    EXPECT_TRUE(af.converged()) << objective << ": " << af.status();
    EXPECT_LE(af.frames_used(), 15) << objective;
    EXPECT_LE(std::abs(af.best_focus_m()), 0.2 * dof) << objective;
  }
}

// A tenth of the light (exposure 1 ms, gain 10: the same grey levels, sqrt(10) times the shot
// noise relative to the signal).
TEST(Autofocus, DimNoisyFramesStillWithinAFifthOfTheDepthOfField) {
  FocusCamera cam("10x", testing::substrate_scene(14), 44);
  cam.controls().exposure_s = 1e-3;
  cam.controls().gain = 10.0;
  const Autofocus af = run(cam, autofocus_params_for(cam.figures(), 100e-6));
  std::printf("10x dim frames: error %+.3f um, %d frames\n", af.best_focus_m() * 1e6, af.frames_used());
  EXPECT_TRUE(af.converged()) << af.status();
  EXPECT_LE(std::abs(af.best_focus_m()), 0.2 * cam.figures().dof_m);
}

// No texture: the measures differ by the noise only. The search says so and leaves the focus
// where it was, instead of returning the noisiest frame's height.
TEST(Autofocus, AFlatTexturelessRegionIsNotConverged) {
  imaging::SceneSnapshot s;
  s.substrate.texture_contrast = 0.0;
  FocusCamera cam("10x", s, 45);
  AutofocusParams p = autofocus_params_for(cam.figures(), 37e-6);
  const Autofocus af = run(cam, p);
  EXPECT_FALSE(af.converged());
  EXPECT_DOUBLE_EQ(af.best_focus_m(), 37e-6);
  EXPECT_LE(af.frames_used(), p.max_frames);
  EXPECT_NE(std::string(af.status()).find("flat"), std::string::npos) << af.status();
}

TEST(Autofocus, APeakAtTheRangesEnd) {
  FocusCamera cam("10x", testing::substrate_scene(15), 46);
  AutofocusParams p = autofocus_params_for(cam.figures(), -90e-6);
  p.range_min_m = -250e-6;
  p.range_max_m = 0.0;  // the substrate's height
  const Autofocus af = run(cam, p);
  std::printf("peak at the range's end: error %+.3f um, %d frames, %s\n", af.best_focus_m() * 1e6,
              af.frames_used(), af.status());
  EXPECT_TRUE(af.converged()) << af.status();
  EXPECT_LE(std::abs(af.best_focus_m()), 0.2 * cam.figures().dof_m);
  EXPECT_LE(af.best_focus_m(), 0.0);
}

TEST(Autofocus, APeakBeyondTheRangeIsNotConverged) {
  FocusCamera cam("10x", testing::substrate_scene(16), 47);
  AutofocusParams p = autofocus_params_for(cam.figures(), -150e-6);
  p.range_min_m = -300e-6;
  p.range_max_m = -40e-6;  // the substrate 40 um above the highest focus
  const Autofocus af = run(cam, p);
  std::printf("peak beyond the range: best %+.3f um, %d frames, %s\n", af.best_focus_m() * 1e6,
              af.frames_used(), af.status());
  EXPECT_FALSE(af.converged()) << af.status();
  EXPECT_DOUBLE_EQ(af.best_focus_m(), -40e-6);  // the end the measure rises to
}

// The search itself, on an exact curve: a Lorentzian peak 1 / (1 + (z / w)^2) plus a floor.
TEST(Autofocus, FindsAnExactLorentzianPeakAnywhereInTheRange) {
  for (const double z0 : {-213e-6, -31e-6, 0.0, 77.7e-6, 260e-6}) {
    AutofocusParams p;
    p.fine_metric = "normalized-variance";
    p.final_step_m = 5e-6;
    Autofocus af(p);
    while (!af.done()) {
      const double u = (af.next_focus_m() - z0) / 10e-6;
      af.observe(0.5 + 100.0 / (1.0 + u * u));
    }
    EXPECT_TRUE(af.converged()) << z0 << ": " << af.status();
    EXPECT_NEAR(af.best_focus_m(), z0, 0.05e-6)
        << "peak at " << z0 * 1e6 << " um, " << af.frames_used() << " frames";
  }
}

// The tool's tips from 100 um above (before this test, `vision autofocus --target tool` at 10x): the
// start sits in the trough between the peak's tail below and a broad rise above (the fingers' body,
// higher along their length, coming into focus), and the first step up reads sharper than the
// start. The search looks on both sides of the start before it climbs, so it goes down to the peak.
TEST(Autofocus, ASlopeOnOneSideOfTheStartDoesNotLeadItAwayFromThePeakOnTheOther) {
  const double z0 = 0.0;
  const auto measure = [&](double z) {
    const double u = (z - z0) / 10e-6;
    const double rise = 0.3 + 1.0 / (1.0 + std::exp(-(z - 200e-6) / 40e-6));  // 0.38 at +100, 1.3 from +400
    return rise + 280.0 / (1.0 + u * u * u * u);
  };
  AutofocusParams p;
  p.range_min_m = -500e-6;
  p.range_max_m = 2000e-6;
  p.start_m = 100e-6;
  p.fine_metric = "normalized-variance";
  ASSERT_GT(measure(140e-6), 1.1 * measure(100e-6)) << "the case: one step up is sharper than the start";
  ASSERT_GT(measure(60e-6), measure(140e-6)) << "the case: one step down is sharper still";
  Autofocus af(p);
  while (!af.done()) af.observe(measure(af.next_focus_m()));
  EXPECT_TRUE(af.converged()) << af.status();
  EXPECT_NEAR(af.best_focus_m(), z0, 1e-6) << af.frames_used() << " frames";
  EXPECT_LE(af.frames_used(), 15);
}

// A small target found on a wide region (reuse_coarse_samples false): the coarse scan measures a
// broad curve whose peak is 6 um off the target's (the tool's silhouette, its body above the tips),
// the refinement the target's own narrow curve. The broad peak lies on the coarse grid, so the first
// stage centres on a coarse sample's height: the refinement measures it again rather than take the
// broad curve's value there as the narrow one's (which the default, a single region, does).
TEST(Autofocus, ACoarseScanOnAnotherRegionIsNeverTakenAsTheRefinementsSample) {
  const double z0 = 20e-6, broad_peak = z0 + 6e-6;
  const auto wide = [&](double z) {
    const double u = (z - broad_peak) / 30e-6;
    return 0.5 + 50.0 / (1.0 + u * u);
  };
  const auto narrow = [&](double z) {
    const double u = (z - z0) / 3e-6;
    return 0.5 + 300.0 / (1.0 + u * u);
  };
  for (const bool reuse : {false, true}) {
    AutofocusParams p;
    p.start_m = broad_peak + 80e-6;         // two coarse steps above the broad peak
    p.fine_metric = "normalized-variance";  // the coarse scan's metric too
    p.final_step_m = 2e-6;
    p.reuse_coarse_samples = reuse;
    Autofocus af(p);
    std::vector<double> coarse_z;
    int measured_again = 0;
    while (!af.done()) {
      const double z = af.next_focus_m();
      if (af.next_is_coarse()) {
        EXPECT_TRUE(af.observations().size() == coarse_z.size()) << "the coarse scan comes first, once";
        coarse_z.push_back(z);
        af.observe(wide(z));
      } else {
        for (const double c : coarse_z) measured_again += std::abs(c - z) < 1e-12;
        af.observe(narrow(z));
      }
    }
    const double err = af.best_focus_m() - z0;
    std::printf(
        "reuse %d: best %+.3f um from the target, %d frames (%zu coarse, %d heights measured again), %s\n",
        reuse, err * 1e6, af.frames_used(), coarse_z.size(), measured_again, af.status());
    if (reuse) {
      EXPECT_EQ(measured_again, 0) << "one region: a coarse sample is the refinement's too";
    } else {
      EXPECT_GE(measured_again, 1);
      EXPECT_TRUE(af.converged()) << af.status();
      EXPECT_NEAR(err, 0.0, 0.1e-6) << af.frames_used() << " frames";
      EXPECT_LE(af.frames_used(), 15);
    }
  }
}

void expect_invalid(const std::function<void(AutofocusParams&)>& edit, const std::string& field) {
  AutofocusParams p;
  edit(p);
  try {
    Autofocus af(p);
    FAIL() << "no error for " << field;
  } catch (const InvalidParams& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.field(), field) << what;
    EXPECT_NE(what.find(field), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(Autofocus, InvalidParamsNameTheField) {
  expect_invalid([](AutofocusParams& p) { p.coarse_step_m = kNaN; }, "coarse_step_m");
  expect_invalid([](AutofocusParams& p) { p.coarse_step_m = -1e-6; }, "coarse_step_m");
  expect_invalid([](AutofocusParams& p) { p.final_step_m = kNaN; }, "final_step_m");
  expect_invalid([](AutofocusParams& p) { p.final_step_m = 1e-3; }, "final_step_m");
  expect_invalid([](AutofocusParams& p) { p.refinement = 0.5; }, "refinement");
  expect_invalid([](AutofocusParams& p) { p.range_min_m = kNaN; }, "range_min_m");
  expect_invalid([](AutofocusParams& p) { p.range_max_m = p.range_min_m; }, "range_max_m");
  expect_invalid([](AutofocusParams& p) { p.start_m = 1.0; }, "start_m");
  expect_invalid([](AutofocusParams& p) { p.start_m = kNaN; }, "start_m");
  expect_invalid([](AutofocusParams& p) { p.max_frames = -1; }, "max_frames");
  expect_invalid([](AutofocusParams& p) { p.min_contrast = kNaN; }, "min_contrast");
  expect_invalid([](AutofocusParams& p) { p.metric = "sharpest"; }, "metric");
  expect_invalid([](AutofocusParams& p) { p.fine_metric = "sharpest"; }, "fine_metric");
  expect_invalid([](AutofocusParams& p) { p.peak_model = "cauchy"; }, "peak_model");
}

TEST(Autofocus, BadMeasuresAndObservingAfterTheEndAreErrors) {
  Autofocus af{AutofocusParams{}};
  EXPECT_THROW(af.observe(kNaN), InvalidInput);
  EXPECT_THROW(af.observe(-1.0), InvalidInput);
  EXPECT_EQ(af.frames_used(), 0);
  AutofocusParams p;
  p.max_frames = 3;
  Autofocus small(p);
  while (!small.done()) small.observe(1.0);
  EXPECT_EQ(small.frames_used(), 3);
  EXPECT_FALSE(small.converged());
  EXPECT_THROW(small.observe(1.0), InvalidInput);
}

}  // namespace
}  // namespace mc::vision
