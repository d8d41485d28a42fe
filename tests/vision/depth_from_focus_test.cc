// Depth from focus: the peak fit on exact curves, and the heights of a
// part's top and of the gripper's tips measured from rendered focus sweeps.

#include "microcobot/vision/depth_from_focus.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "focus_scenes.h"
#include "microcobot/core/error.h"
#include "microcobot/vision/autofocus.h"

namespace mc::vision {
// The file's own namespace: its helpers keep their names beside the other test files of the
// module in a unity build (MC_UNITY_TESTS).
namespace depth_from_focus_test {
namespace {

using testing::FocusCamera;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Unevenly spaced samples of the curve each model is exact for: the vertex comes back exactly.
TEST(DepthFromFocus, EachModelIsExactOnItsCurve) {
  const double z0 = 12.3e-6, w = 5e-6;
  const std::vector<double> zs = {-3e-6, 4e-6, 9e-6, 13e-6, 14.5e-6, 21e-6, 30e-6};
  std::vector<FocusSample> lorentz, gauss;
  for (double z : zs) {
    const double u = (z - z0) / w;
    lorentz.push_back({z, 7.0 / (1.0 + u * u)});
    gauss.push_back({z, 7.0 * std::exp(-0.5 * u * u)});
  }
  FocusPeakParams p;
  p.peak_fraction = 0.0;  // every sample in the fit
  const FocusPeak l = focus_peak(lorentz, p);
  ASSERT_TRUE(l.found) << l.reason;
  EXPECT_NEAR(l.z_m, z0, 1e-12);
  EXPECT_EQ(l.fitted, 7);
  p.model = PeakModel::kGaussian;
  const FocusPeak g = focus_peak(gauss, p);
  ASSERT_TRUE(g.found) << g.reason;
  EXPECT_NEAR(g.z_m, z0, 1e-12);
  // The wrong model on a skewed set of samples is biased: the fit is not a copy of the data.
  const FocusPeak wrong = focus_peak(lorentz, p);
  EXPECT_GT(std::abs(wrong.z_m - z0), 1e-8);
  // The three-point vertex: (0, 0), (1, 1), (3, -3) lie on y = -z^2 + 2 z, vertex at 1.
  EXPECT_NEAR(parabola_vertex(0.0, 0.0, 1.0, 1.0, 3.0, -3.0), 1.0, 1e-12);
  EXPECT_NEAR(parabola_vertex(3.0, -3.0, 0.0, 0.0, 1.0, 1.0), 1.0, 1e-12);
}

TEST(DepthFromFocus, NoPeakIsReportedNotInvented) {
  // Flat (noise only): under the minimum contrast.
  std::vector<FocusSample> flat;
  for (int i = 0; i < 9; ++i) flat.push_back({i * 1e-6, 10.0 + 0.01 * ((i * 7) % 3)});
  const FocusPeak f = focus_peak(flat);
  EXPECT_FALSE(f.found);
  EXPECT_NE(std::string(f.reason).find("flat"), std::string::npos) << f.reason;
  // Rising to the sweep's end: the peak may lie beyond it.
  std::vector<FocusSample> rising;
  for (int i = 0; i < 9; ++i) rising.push_back({i * 1e-6, 1.0 + i});
  const FocusPeak r = focus_peak(rising);
  EXPECT_FALSE(r.found);
  EXPECT_DOUBLE_EQ(r.z_m, 8e-6);
  EXPECT_NE(std::string(r.reason).find("end"), std::string::npos) << r.reason;
  EXPECT_FALSE(focus_peak(std::vector<FocusSample>{}).found);
}

TEST(DepthFromFocus, BadSamplesAreOneLineErrors) {
  for (const FocusSample bad : {FocusSample{kNaN, 1.0}, FocusSample{0.0, -1.0}, FocusSample{0.0, kInf}}) {
    const std::vector<FocusSample> s = {{-1e-6, 1.0}, bad, {1e-6, 1.0}};
    try {
      focus_peak(s);
      FAIL() << "no error";
    } catch (const InvalidInput& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("focus sample 1"), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

// A sweep of `n` frames at `step` around `z_guess` (the height a part is expected at, off by
// `guess_error`), measured with Tenengrad: the estimate against the true height.
double sweep_estimate(FocusCamera& cam, double z_guess, double step, int n, const imaging::PixelRoi& roi) {
  std::vector<FocusSample> sweep;
  for (int k = -n / 2; k <= n / 2; ++k) {
    const double z = z_guess + k * step;
    sweep.push_back({z, sharpness(cam.frame_at(z), roi, FocusMetric::kTenengrad)});
  }
  const FocusPeak peak = focus_peak(sweep);
  EXPECT_TRUE(peak.found) << peak.reason;
  return peak.z_m;
}

// The goal's tolerance: a fifth of the depth of field, and 0.3 um.
double goal_tolerance(const imaging::OpticsFigures& f) { return std::min(0.2 * f.dof_m, 0.3e-6); }

TEST(DepthFromFocus, HeightOfAPartsTopFromASweep) {
  for (const double z_top : {180e-6, 262.5e-6}) {
    FocusCamera cam("10x", testing::part_scene(6, z_top), 31);
    const double dof = cam.figures().dof_m;
    // 17 frames half a depth of field apart, centred 3.3 um off the true height.
    const double z = sweep_estimate(cam, z_top + 3.3e-6, 0.5 * dof, 17, testing::kFocusRoi);
    std::printf("part top at %.1f um: depth from focus %.3f um, error %+.3f um (tolerance %.3f um)\n",
                z_top * 1e6, z * 1e6, (z - z_top) * 1e6, goal_tolerance(cam.figures()) * 1e6);
    EXPECT_NEAR(z, z_top, goal_tolerance(cam.figures()));
  }
}

// The search's own observations (those of its fine measure) are a sweep too.
TEST(DepthFromFocus, HeightOfAPartsTopFromAnAutofocusSearch) {
  const double z_top = 205e-6;
  FocusCamera cam("10x", testing::part_scene(9, z_top), 33);
  Autofocus af(autofocus_params_for(cam.figures(), z_top - 80e-6));
  while (!af.done()) af.observe(cam.measure(af.next_focus_m(), af.next_metric()));
  ASSERT_TRUE(af.converged()) << af.status();
  std::vector<FocusSample> fine;
  for (std::size_t i = 0; i < af.observations().size(); ++i)
    if (af.observation_metrics()[i] == FocusMetric::kTenengrad) fine.push_back(af.observations()[i]);
  const FocusPeak peak = focus_peak(fine);
  ASSERT_TRUE(peak.found) << peak.reason;
  std::printf("part top at %.1f um from the search's %zu Tenengrad frames: %.3f um (search: %.3f um)\n",
              z_top * 1e6, fine.size(), peak.z_m * 1e6, af.best_focus_m() * 1e6);
  EXPECT_NEAR(peak.z_m, z_top, goal_tolerance(cam.figures()));
}

TEST(DepthFromFocus, HeightOfTheGrippersTips) {
  const double z_tip = 150e-6;
  imaging::SceneSnapshot s = testing::substrate_scene(8);
  for (int side : {-1, 1}) {
    imaging::Finger f;
    f.tip_x_m = side * 45e-6;  // two fingers 50 um apart, their tips in the view
    f.tip_y_m = -30e-6;
    f.z_tip_m = z_tip;
    s.fingers.push_back(f);
  }
  FocusCamera cam("10x", s, 32);
  const double dof = cam.figures().dof_m;
  const double z = sweep_estimate(cam, z_tip - 2.1e-6, 0.5 * dof, 17, testing::kFocusRoi);
  std::printf("fingers' tips at %.1f um: depth from focus %.3f um, error %+.3f um\n", z_tip * 1e6, z * 1e6,
              (z - z_tip) * 1e6);
  EXPECT_NEAR(z, z_tip, goal_tolerance(cam.figures()));
}

}  // namespace
}  // namespace depth_from_focus_test
}  // namespace mc::vision
