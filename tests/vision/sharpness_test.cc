// Focus measures: their values on hand-computed frames, their peaks at the
// true focus on rendered frames (a textured substrate, a part's edge), and the ROI's validation.

#include "microcobot/vision/sharpness.h"

#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "focus_scenes.h"
#include "microcobot/core/error.h"

namespace mc::vision {
namespace {

using testing::FocusCamera;

imaging::Frame make_frame(int w, int h, std::vector<std::uint16_t> pixels) {
  imaging::Frame f;
  f.width = w, f.height = h, f.bit_depth = 12;
  f.pixels = std::move(pixels);
  return f;
}

// Values worked by hand from the definitions (sharpness.h).
TEST(Sharpness, HandComputedValues) {
  // 2 x 2 checker 0, 2 / 2, 0: mean 1, variance 1, normalised variance var / mean = 1.
  EXPECT_DOUBLE_EQ(normalized_variance(make_frame(2, 2, {0, 2, 2, 0}), imaging::PixelRoi{0, 0, 2, 2}), 1.0);
  // A uniform frame has none; a black one is 0, not NaN.
  EXPECT_DOUBLE_EQ(normalized_variance(make_frame(2, 2, {7, 7, 7, 7}), imaging::PixelRoi{0, 0, 2, 2}), 0.0);
  EXPECT_DOUBLE_EQ(normalized_variance(make_frame(2, 2, {0, 0, 0, 0}), imaging::PixelRoi{0, 0, 2, 2}), 0.0);
  // 3 x 3, a vertical step 0 | 0 | 10: at the centre Gx = (10 + 2 * 10 + 10) - 0 = 40, Gy = 0.
  const imaging::Frame step = make_frame(3, 3, {0, 0, 10, 0, 0, 10, 0, 0, 10});
  EXPECT_DOUBLE_EQ(tenengrad(step, imaging::PixelRoi{0, 0, 3, 3}), 1600.0);
  EXPECT_DOUBLE_EQ(tenengrad(step, imaging::PixelRoi{0, 0, 3, 3}, 1600.0),
                   0.0);  // at the threshold: left out
  EXPECT_DOUBLE_EQ(tenengrad(step, imaging::PixelRoi{0, 0, 3, 3}, 1599.0), 1600.0);
  // Brenner: one pair per row, (10 - 0)^2 each.
  EXPECT_DOUBLE_EQ(brenner(step, imaging::PixelRoi{0, 0, 3, 3}), 100.0);
  // A ROI measures only its own pixels: the left two columns are flat.
  EXPECT_DOUBLE_EQ(normalized_variance(step, imaging::PixelRoi{0, 0, 2, 3}), 0.0);
}

TEST(Sharpness, MetricNamesRoundTrip) {
  for (FocusMetric m : {FocusMetric::kNormalizedVariance, FocusMetric::kTenengrad, FocusMetric::kBrenner})
    EXPECT_EQ(parse_focus_metric(focus_metric_name(m)), m);
  EXPECT_EQ(parse_focus_metric("normalized-variance"), FocusMetric::kNormalizedVariance);
  try {
    parse_focus_metric("laplacian");
    FAIL() << "no error";
  } catch (const InvalidInput& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("laplacian"), std::string::npos) << what;
    EXPECT_NE(what.find("tenengrad"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

void expect_roi_error(const imaging::PixelRoi& roi, const std::string& words, FocusMetric metric) {
  const imaging::Frame f = make_frame(8, 6, std::vector<std::uint16_t>(48, 100));
  try {
    sharpness(f, roi, metric);
    FAIL() << "no error for ROI " << roi.x << " " << roi.y << " " << roi.width << " " << roi.height;
  } catch (const InvalidInput& e) {
    const std::string what = e.what();
    std::printf("%s\n", what.c_str());
    EXPECT_NE(what.find("ROI x=" + std::to_string(roi.x)), std::string::npos) << what;
    EXPECT_NE(what.find(words), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(Sharpness, BadRoisAreOneLineErrorsNamingTheRoi) {
  for (FocusMetric m : {FocusMetric::kNormalizedVariance, FocusMetric::kTenengrad, FocusMetric::kBrenner}) {
    expect_roi_error(imaging::PixelRoi{0, 0, 0, 4}, "empty", m);
    expect_roi_error(imaging::PixelRoi{2, 2, 3, -1}, "empty", m);
    expect_roi_error(imaging::PixelRoi{6, 0, 3, 3}, "not inside the frame of the 8 x 6 image", m);
    expect_roi_error(imaging::PixelRoi{-1, 0, 3, 3}, "not inside", m);
    expect_roi_error(imaging::PixelRoi{0, 4, 3, 3}, "not inside", m);
    expect_roi_error(imaging::PixelRoi{100, 100, 4, 4}, "not inside", m);
  }
  expect_roi_error(imaging::PixelRoi{0, 0, 2, 2}, "too small", FocusMetric::kTenengrad);
  expect_roi_error(imaging::PixelRoi{0, 0, 2, 6}, "too small", FocusMetric::kBrenner);
  // The whole frame is fine.
  const imaging::Frame f = make_frame(8, 6, std::vector<std::uint16_t>(48, 100));
  EXPECT_DOUBLE_EQ(sharpness(f, imaging::full_roi(f), FocusMetric::kTenengrad), 0.0);
}

// Through focus, each measure is largest at the surface's height and falls off on both sides.
void expect_peak_at(FocusCamera& cam, double z_true, double half_span, double step, FocusMetric metric,
                    const char* what, double min_contrast = 1.2) {
  double best_z = 0.0, best = -1.0, at_minus = 0.0, at_plus = 0.0;
  const int n = static_cast<int>(half_span / step + 0.5);
  for (int k = -n; k <= n; ++k) {
    const double z = z_true + k * step;
    const double f = cam.measure(z, metric);
    if (f > best) best = f, best_z = z;
    if (k == -n) at_minus = f;
    if (k == n) at_plus = f;
  }
  const double dof = cam.figures().dof_m;
  std::printf("%s %s: peak at %+.2f um (DOF %.2f um), F(peak) / F(-%.0f um) %.2f, / F(+%.0f um) %.2f\n", what,
              focus_metric_name(metric), (best_z - z_true) * 1e6, dof * 1e6, half_span * 1e6, best / at_minus,
              half_span * 1e6, best / at_plus);
  // Within a quarter of the depth of field (and half a sample step): near the top the measures
  // are flat to under 1 % (the sensor's noise decides the last steps).
  EXPECT_LE(std::abs(best_z - z_true), 0.25 * dof + 0.5 * step) << what << " " << focus_metric_name(metric);
  EXPECT_GT(best, min_contrast * at_minus) << what << " " << focus_metric_name(metric);
  EXPECT_GT(best, min_contrast * at_plus) << what << " " << focus_metric_name(metric);
}

TEST(Sharpness, EveryMetricPeaksAtTheTexturedSubstrate) {
  for (const char* objective : {"5x", "10x", "20x"}) {
    FocusCamera cam(objective, testing::substrate_scene(3), 21);
    const double dof = cam.figures().dof_m;
    for (FocusMetric m : {FocusMetric::kNormalizedVariance, FocusMetric::kTenengrad, FocusMetric::kBrenner})
      expect_peak_at(cam, 0.0, 3.0 * dof, 0.125 * dof, m, (std::string("substrate ") + objective).c_str());
  }
  // At 50x the in-focus PSF spans about 5 pixels (sigma 0.23 um, pixel 0.106 um): the gradients
  // between neighbouring pixels are mostly the sensor's noise (Tenengrad gains 18 % in focus,
  // Brenner 8 %); the variance keeps the texture's contrast.
  FocusCamera cam("50x", testing::substrate_scene(3), 21);
  const double dof = cam.figures().dof_m;
  expect_peak_at(cam, 0.0, 3.0 * dof, 0.125 * dof, FocusMetric::kNormalizedVariance, "substrate 50x");
  expect_peak_at(cam, 0.0, 3.0 * dof, 0.125 * dof, FocusMetric::kTenengrad, "substrate 50x", 1.1);
}

TEST(Sharpness, EveryMetricPeaksAtAPartsTop) {
  const double z_top = 220e-6;
  FocusCamera cam("10x", testing::part_scene(4, z_top), 22);
  const double dof = cam.figures().dof_m;
  // The variance of a bright top beside the darker substrate is mostly the step's, which blur
  // hardly changes (6 % over 3 DOF); the gradients gain a factor 3.
  expect_peak_at(cam, z_top, 3.0 * dof, 0.125 * dof, FocusMetric::kNormalizedVariance, "part top 10x", 1.03);
  expect_peak_at(cam, z_top, 3.0 * dof, 0.125 * dof, FocusMetric::kTenengrad, "part top 10x", 2.0);
  expect_peak_at(cam, z_top, 3.0 * dof, 0.125 * dof, FocusMetric::kBrenner, "part top 10x", 2.0);
}

}  // namespace
}  // namespace mc::vision
