// The Cramér-Rao bound of a target's translation (the tracker's goal: within 2x of the
// localisation bound for the frame's SNR), and the tracker measured against it on rendered frames.

#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/imaging/renderer.h"
#include "microcobot/vision/localisation_bound.h"
#include "microcobot/vision/template_tracker.h"
#include "tracking_scenes.h"

namespace mc::vision {
namespace {

using testing::kH;
using testing::kTop;
using testing::kW;
using testing::small_camera;

// A 300 um part, 100 um thick, its upper left corner at the image's centre plus (du, dv) px.
imaging::SceneSnapshot corner_at(double du_px, double dv_px, double pixel_m) {
  imaging::SceneSnapshot s;
  s.substrate.texture_seed = 7;
  imaging::Part p;
  p.x_m = 150e-6 + du_px * pixel_m;
  p.y_m = -150e-6 - dv_px * pixel_m;
  p.size_x_m = p.size_y_m = 300e-6;
  p.z_top_m = kTop;
  s.parts.push_back(p);
  return s;
}

struct Bench {
  imaging::Renderer renderer{small_camera()};
  imaging::CameraControls controls;
  imaging::PixelRoi roi{kW / 2 - 40, kH / 2 - 40, 80, 80};
  explicit Bench(double exposure_s) {
    controls = renderer.default_controls();
    controls.focus_z_m = kTop;
    controls.exposure_s = exposure_s;
  }
  LocalisationBound bound() {
    const double pixel_m = renderer.camera().pixel_size_m();
    return translation_bound(
        [&](double du, double dv) { return renderer.render_expected(corner_at(du, dv, pixel_m), controls); },
        renderer.camera().sensor, controls.exposure_s, controls.gain, roi);
  }
};

TEST(LocalisationBound, ShrinksAsTheSquareRootOfTheLight) {
  Bench dim(2.5e-3), bright(10e-3);
  const LocalisationBound a = dim.bound(), b = bright.bound();
  EXPECT_GT(a.sigma_u_px, 0.0);
  // Four times the light, shot-noise limited: half the bound (read noise makes it a bit less).
  EXPECT_NEAR(b.sigma_u_px / a.sigma_u_px, 0.5, 0.05);
  EXPECT_NEAR(b.sigma_v_px / a.sigma_v_px, 0.5, 0.05);
  // A corner of two equal edges: the same along both axes.
  EXPECT_NEAR(b.sigma_u_px / b.sigma_v_px, 1.0, 0.1);
}

TEST(LocalisationBound, TheTrackerComesToAboutTwiceTheBound) {
  Bench s(10e-3);
  const LocalisationBound bound = s.bound();
  const double pixel_m = s.renderer.camera().pixel_size_m();
  imaging::Frame frame;
  s.renderer.render(corner_at(0.0, 0.0, pixel_m), s.controls, 1, 0, frame);
  TemplateTracker tracker;
  tracker.set_template(frame, s.roi);
  const double u0 = tracker.last().u_px, v0 = tracker.last().v_px;
  // Sub-pixel positions, each under 20 noise draws. Measured (this test's printout): 1.4-2.4x of
  // the bound per phase and axis, 1.9-2.0x pooled; the goal is 2x. Not closer: ECC is an
  // unweighted least-squares fit (the bound weighs the brighter, noisier pixels less), the
  // template is itself a noisy frame, and the blurred substrate behind the corner, which does not
  // move with the part, pulls the estimate by ~0.005 px.
  double pooled = 0.0;
  for (const auto& [du, dv] : {std::pair{0.3, 0.6}, {0.5, 0.5}, {0.9, 0.1}, {0.0, 0.25}}) {
    double su2 = 0.0, sv2 = 0.0;
    constexpr int kDraws = 20;
    for (int k = 1; k <= kDraws; ++k) {
      s.renderer.render(corner_at(du, dv, pixel_m), s.controls, 1, static_cast<std::uint64_t>(k), frame);
      const TrackEstimate e = tracker.track_near(frame, u0 + du, v0 + dv);
      ASSERT_TRUE(e.found);
      su2 += std::pow(e.u_px - u0 - du, 2);
      sv2 += std::pow(e.v_px - v0 - dv, 2);
    }
    const double rms_u = std::sqrt(su2 / kDraws), rms_v = std::sqrt(sv2 / kDraws);
    std::printf("phase (%.2f, %.2f): bound %.4f / %.4f px, tracker rms %.4f / %.4f px: %.2fx / %.2fx\n", du,
                dv, bound.sigma_u_px, bound.sigma_v_px, rms_u, rms_v, rms_u / bound.sigma_u_px,
                rms_v / bound.sigma_v_px);
    pooled += (std::pow(rms_u / bound.sigma_u_px, 2) + std::pow(rms_v / bound.sigma_v_px, 2)) / 8.0;
  }
  pooled = std::sqrt(pooled);
  std::printf("pooled: %.2fx the bound\n", pooled);
  EXPECT_LT(pooled, 2.25) << "x the bound (goal 2x)";
  EXPECT_GT(pooled, 1.0) << "no estimator beats the bound: the bound or the truth is wrong";
}

TEST(LocalisationBound, RefusesAnRoiOutsideTheSensorOrWithoutAnEdge) {
  Bench s(10e-3);
  s.roi = {300, 10, 40, 40};
  EXPECT_THROW(s.bound(), InvalidInput);
  imaging::Renderer r(small_camera());
  imaging::SceneSnapshot flat;
  flat.substrate.texture_contrast = 0.0;
  EXPECT_THROW(
      translation_bound([&](double, double) { return r.render_expected(flat, r.default_controls()); },
                        r.camera().sensor, 10e-3, 1.0, {10, 10, 40, 40}),
      InvalidInput);
}

}  // namespace
}  // namespace mc::vision
