// The template tracker on rendered frames: a part's corner followed with
// sub-pixel error at the default sensor's noise, no pull toward whole pixels, lost when the part
// leaves the field and re-acquired when it returns; bad templates refused in one line.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/imaging/renderer.h"
#include "microcobot/vision/template_tracker.h"
#include "tracking_scenes.h"

namespace mc::vision {
namespace {

using testing::kH;
using testing::kTop;
using testing::kW;
using testing::small_camera;

// A 300 um brass part 100 um thick, its top in focus, on the textured steel substrate (which is
// then out of focus: a template that also holds a sharp static background is pulled toward it).
imaging::SceneSnapshot part_at(double x_m, double y_m) {
  imaging::SceneSnapshot s;
  s.substrate.texture_seed = 7;
  imaging::Part p;
  p.x_m = x_m;
  p.y_m = y_m;
  p.size_x_m = p.size_y_m = 300e-6;
  p.z_top_m = kTop;
  s.parts.push_back(p);
  return s;
}

// The part's upper-left corner at the image's centre when the part is at (x0, y0).
constexpr double kX0 = 150e-6, kY0 = -150e-6;

struct Fixture {
  imaging::Renderer renderer{small_camera()};
  imaging::Frame frame;
  void render(double x_m, double y_m, std::uint64_t index) {
    imaging::CameraControls c = renderer.default_controls();
    c.focus_z_m = kTop;
    renderer.render(part_at(x_m, y_m), c, 11, index, frame);
  }
  TemplateTracker start(const TrackerParams& params = {}) {
    render(kX0, kY0, 0);
    TemplateTracker t(params);
    t.set_template(frame, imaging::PixelRoi{kW / 2 - 40, kH / 2 - 40, 80, 80});
    return t;
  }
};

TEST(TemplateTracker, FollowsAPartWithSubPixelErrorAndNoPullTowardWholePixels) {
  Fixture f;
  TemplateTracker tracker = f.start();
  const double u0 = tracker.last().u_px, v0 = tracker.last().v_px;
  const double pixel_m = f.renderer.camera().pixel_size_m();
  // Sub-pixel phases across one pixel (0.1 px apart) along a diagonal: the error must not depend
  // on the phase (pixel locking would pull it toward 0 and 1, a sawtooth of the phase).
  double sum2 = 0.0, mean_first_half = 0.0, mean_second_half = 0.0;
  constexpr int kSteps = 20;
  for (int k = 1; k <= kSteps; ++k) {
    const double shift_px = 0.1 * k;
    f.render(kX0 + shift_px * pixel_m, kY0 - shift_px * pixel_m, static_cast<std::uint64_t>(k));
    const TrackEstimate e = tracker.track(f.frame);
    ASSERT_TRUE(e.found) << "frame " << k;
    EXPECT_GT(e.confidence, 0.95);
    const double eu = e.u_px - (u0 + shift_px), ev = e.v_px - (v0 + shift_px);
    sum2 += eu * eu + ev * ev;
    const double phase = shift_px - std::floor(shift_px);
    (phase < 0.5 ? mean_first_half : mean_second_half) += 0.5 * (eu + ev) / (kSteps / 2.0);
  }
  const double rms = std::sqrt(sum2 / kSteps);
  EXPECT_LT(rms, 0.05) << "px (goal: <= 0.05 px at the default noise)";
  // Pixel locking biases phases below 1/2 backwards and above 1/2 forwards (toward the nearest
  // whole pixel): the halves' mean errors would differ by a sizeable fraction of a pixel.
  EXPECT_LT(std::abs(mean_first_half - mean_second_half), 0.02) << "px";
}

// The gripper's tips at 5x, 150 um over a part whose edge passes under them, moved by 0.1 px
// steps across a pixel in u and v and then 30 um over the part's edge: tracked with the tool's
// template (both tips, their ends and the gap, centred on the tool point) and the 1.5 px
// high-pass, the error stays under 0.05 px rms with no pull toward whole pixels.
// Without the high-pass the part's changing glow biased it (0.49 px rms in a seeded case); with
// a finger drawn as segments laid one over the other, their seams did (0.2 px at 5x).
TEST(TemplateTracker, FollowsTheToolsTipsOverAPartsGlowWithoutPixelLocking) {
  imaging::CameraParams cam = small_camera();
  cam.objective = imaging::objective_by_name("5x");
  imaging::Renderer renderer(cam);
  const double pixel_m = cam.pixel_size_m(), z_tips = 450e-6;
  const auto scene_at = [&](double x_m, double y_m) {
    imaging::SceneSnapshot s;
    s.substrate.texture_seed = 3;
    imaging::Part p;
    p.x_m = 120e-6;  // its left edge 30 um right of the tool at the start
    p.size_x_m = p.size_y_m = 300e-6;
    p.z_top_m = 300e-6;
    s.parts.push_back(p);
    for (const double side : {-1.0, 1.0}) {
      imaging::Finger f;
      f.tip_x_m = x_m + side * 30e-6;  // 20 um apart
      f.tip_y_m = y_m - 20e-6;
      f.z_tip_m = z_tips;
      f.rise = 0.5;
      s.fingers.push_back(f);
    }
    return s;
  };
  imaging::CameraControls c = renderer.default_controls();
  c.focus_z_m = z_tips;
  imaging::Frame frame;
  renderer.render(scene_at(0.0, 0.0), c, 21, 0, frame);
  TrackerParams params;
  params.ecc_highpass_px = 1.5;
  TemplateTracker tracker(params);
  tracker.set_template(frame, {kW / 2 - 48, kH / 2 - 48, 96, 96});
  const double u0 = tracker.last().u_px, v0 = tracker.last().v_px;
  double sum2 = 0.0, worst = 0.0, first_half = 0.0, second_half = 0.0;
  int n = 0;
  const auto track = [&](double du_px, double dv_px, std::uint64_t index) {
    renderer.render(scene_at(du_px * pixel_m, -dv_px * pixel_m), c, 21, index, frame);
    const TrackEstimate e = tracker.track(frame);
    EXPECT_TRUE(e.found) << "frame " << index;
    const double eu = e.u_px - (u0 + du_px), ev = e.v_px - (v0 + dv_px);
    sum2 += eu * eu + ev * ev;
    worst = std::max(worst, std::hypot(eu, ev));
    ++n;
    return std::pair(eu, ev);
  };
  constexpr int kSteps = 20;
  for (int k = 1; k <= kSteps; ++k) {  // sub-pixel phases, diagonally
    const double shift = 0.1 * k;
    const auto [eu, ev] = track(shift, shift, static_cast<std::uint64_t>(k));
    const double phase = shift - std::floor(shift);
    (phase < 0.5 ? first_half : second_half) += 0.5 * (eu + ev) / (kSteps / 2.0);
  }
  for (int k = 1; k <= 30; ++k)  // 30 um toward the part: its edge passes under the gap
    track(2.0 + k * 1e-6 / pixel_m, 2.0, static_cast<std::uint64_t>(kSteps + k));
  const double rms = std::sqrt(sum2 / n);
  std::printf("tool's tips at 5x: rms %.4f px, worst %.4f px, phase halves %+.4f / %+.4f px\n", rms, worst,
              first_half, second_half);
  EXPECT_LT(rms, 0.05) << "px (goal: <= 0.05 px at the default noise)";
  EXPECT_LT(std::abs(first_half - second_half), 0.02) << "px";
}

// The gripper's two fingers crossing the template's edges, standing
// still: the estimate must stay on the template's own position. (A pre-filter padded at the
// template's border but not in the frame's window put it 0.14 px off.)
TEST(TemplateTracker, BarsCrossingTheTemplatesEdgeDoNotBiasAStillTarget) {
  imaging::Renderer renderer(small_camera());
  imaging::SceneSnapshot s;
  s.substrate.texture_seed = 5;
  for (const double side : {-1.0, 1.0}) {
    imaging::Finger f;
    f.tip_x_m = side * 30e-6;
    f.tip_y_m = -20e-6;
    f.rise = 0.5;
    s.fingers.push_back(f);
  }
  imaging::CameraControls c = renderer.default_controls();
  c.focus_z_m = 0.0;  // the tips in focus, the bars rising out of it
  imaging::Frame frame;
  renderer.render(s, c, 9, 0, frame);
  TemplateTracker tracker;
  // The template's lower edge cuts across the tips (sharp), its upper edge across the bars.
  tracker.set_template(frame, {kW / 2 - 48, kH / 2 - 72, 96, 96});
  const double u0 = tracker.last().u_px, v0 = tracker.last().v_px;
  double mean_u = 0.0, mean_v = 0.0;
  for (int k = 1; k <= 10; ++k) {
    renderer.render(s, c, 9, static_cast<std::uint64_t>(k), frame);
    const TrackEstimate e = tracker.track(frame);
    ASSERT_TRUE(e.found);
    mean_u += (e.u_px - u0) / 10.0;
    mean_v += (e.v_px - v0) / 10.0;
  }
  EXPECT_LT(std::abs(mean_u), 0.02) << "px";
  EXPECT_LT(std::abs(mean_v), 0.02) << "px";
}

// The part turned about its corner by 1.5 degrees a frame to 15 degrees, tracked with the Euclidean warp: the
// angle within 0.2 degrees and the corner still within a twentieth of a pixel.
TEST(TemplateTracker, FollowsAPartsTurnWithinAFifthOfADegree) {
  imaging::Renderer renderer(small_camera());
  imaging::CameraControls c = renderer.default_controls();
  c.focus_z_m = kTop;
  // The part's centre placed so that its upper left corner stays at the image's centre.
  const auto render = [&](double angle, std::uint64_t index, imaging::Frame& out) {
    imaging::SceneSnapshot s = part_at(0.0, 0.0);
    imaging::Part& p = s.parts.front();
    const double h = 150e-6;
    p.angle_rad = angle;
    p.x_m = h * std::cos(angle) + h * std::sin(angle);  // R(angle) (h, -h)
    p.y_m = h * std::sin(angle) - h * std::cos(angle);
    renderer.render(s, c, 11, index, out);
  };
  imaging::Frame frame;
  render(0.0, 0, frame);
  TrackerParams params;
  params.rotation = true;
  TemplateTracker tracker(params);
  tracker.set_template(frame, imaging::PixelRoi{kW / 2 - 48, kH / 2 - 48, 96, 96});
  const double u0 = tracker.last().u_px, v0 = tracker.last().v_px;
  const double corner_u = renderer.u_of_x(0.0), corner_v = renderer.v_of_y(0.0);
  double worst_deg = 0.0;
  for (int k = 1; k <= 10; ++k) {
    const double angle = 1.5 * k * M_PI / 180.0;
    render(angle, static_cast<std::uint64_t>(k), frame);
    const TrackEstimate e = tracker.track(frame);
    ASSERT_TRUE(e.found) << k;
    worst_deg = std::max(worst_deg, std::abs(e.angle_rad - angle) * 180.0 / M_PI);
    // The template's centre turns about the corner with the part.
    const double du = u0 - corner_u, dv = v0 - corner_v;  // image frame, rows down
    const double eu = corner_u + std::cos(angle) * du + std::sin(angle) * dv;
    const double ev = corner_v - std::sin(angle) * du + std::cos(angle) * dv;
    EXPECT_NEAR(e.u_px, eu, 0.05) << k;
    EXPECT_NEAR(e.v_px, ev, 0.05) << k;
  }
  EXPECT_LT(worst_deg, 0.2);
}

TEST(TemplateTracker, LosesAPartThatLeavesTheFieldAndReacquiresItWhenItReturns) {
  Fixture f;
  TemplateTracker tracker = f.start();
  const double u0 = tracker.last().u_px;
  // Far out of the field: not found, and the last known position is kept.
  f.render(kX0 + 2e-3, kY0, 1);
  const TrackEstimate gone = tracker.track(f.frame);
  EXPECT_FALSE(gone.found);
  // Back 30 px from where it was lost (beyond the search window's reach from a lost state).
  const double back_px = 30.0;
  f.render(kX0 - back_px * f.renderer.camera().pixel_size_m(), kY0, 2);
  const TrackEstimate back = tracker.track(f.frame);
  ASSERT_TRUE(back.found);
  EXPECT_TRUE(back.reacquired);
  // Found again (within a quarter pixel: 30 px from where it was taken, the blurred substrate
  // behind the corner, which does not move with the part, pulls the estimate by ~0.1 px).
  EXPECT_NEAR(back.u_px, u0 - back_px, 0.25);
  // And followed normally afterwards.
  f.render(kX0 - (back_px + 0.5) * f.renderer.camera().pixel_size_m(), kY0, 3);
  const TrackEstimate next = tracker.track(f.frame);
  ASSERT_TRUE(next.found);
  EXPECT_FALSE(next.reacquired);
  EXPECT_NEAR(next.u_px, u0 - back_px - 0.5, 0.25);
}

TEST(TemplateTracker, SaysWhetherATemplatePredictedAtAPointFitsInTheFrame) {
  Fixture f;
  EXPECT_FALSE(TemplateTracker().fits(kW / 2.0, kH / 2.0, kW, kH)) << "no template: nothing fits";
  TemplateTracker tracker = f.start();  // an 80 x 80 template: its centre 39.5 px from its left column
  EXPECT_TRUE(tracker.fits(tracker.last().u_px, tracker.last().v_px, kW, kH)) << "where it was taken";
  const double v = kH / 2.0;
  EXPECT_TRUE(tracker.fits(39.5, v, kW, kH)) << "its left column on the frame's first";
  EXPECT_FALSE(tracker.fits(38.5, v, kW, kH)) << "a pixel further left";
  EXPECT_TRUE(tracker.fits(kW - 40.5, v, kW, kH)) << "its right column on the frame's last";
  EXPECT_FALSE(tracker.fits(kW - 39.5, v, kW, kH));
  EXPECT_FALSE(tracker.fits(kW / 2.0, -20.0, kW, kH)) << "above the top";
  EXPECT_FALSE(tracker.fits(std::nan(""), v, kW, kH));
}

TEST(TemplateTracker, APredictionFindsAJumpBeyondTheSearchWindow) {
  Fixture f;
  TrackerParams p;
  p.search_margin_px = 8;
  TemplateTracker tracker = f.start(p);
  const double u0 = tracker.last().u_px, v0 = tracker.last().v_px;
  const double jump_px = 60.0;
  f.render(kX0 + jump_px * f.renderer.camera().pixel_size_m(), kY0, 1);
  const TrackEstimate e = tracker.track_near(f.frame, u0 + jump_px + 3.0, v0 - 2.0);
  ASSERT_TRUE(e.found);
  EXPECT_FALSE(e.reacquired) << "found in the window around the prediction";
  EXPECT_NEAR(e.u_px, u0 + jump_px, 0.05);
  EXPECT_NEAR(e.v_px, v0, 0.05);
}

TEST(TemplateTracker, ATargetBetweenTwoPredictionsIsFoundInTheWindowAlongThem) {
  // A finger closing on a part stops anywhere between where its drive puts it and where it was:
  // the window spans both; the target 40 px from either end is found there, not by a whole-frame
  // search.
  Fixture f;
  TrackerParams p;
  p.search_margin_px = 8;
  TemplateTracker tracker = f.start(p);
  const double u0 = tracker.last().u_px, v0 = tracker.last().v_px;
  f.render(kX0 + 40.0 * f.renderer.camera().pixel_size_m(), kY0, 1);
  const TrackEstimate e = tracker.track_along(f.frame, u0, v0, u0 + 80.0, v0);
  ASSERT_TRUE(e.found);
  EXPECT_FALSE(e.reacquired) << "found in the window along the predictions";
  // Within a tenth of a pixel: 40 px from where it was taken, the blurred substrate behind the
  // corner pulls by ~0.06 px (as in the test above).
  EXPECT_NEAR(e.u_px, u0 + 40.0, 0.1);
  EXPECT_NEAR(e.v_px, v0, 0.1);
  EXPECT_THROW(tracker.track_along(f.frame, u0, v0, std::nan(""), v0), InvalidInput);
}

TEST(TemplateTracker, RefusesBadTemplatesAndInputsInOneLine) {
  Fixture f;
  f.render(kX0, kY0, 0);
  TemplateTracker tracker;
  const auto message = [&](const imaging::PixelRoi& roi) {
    try {
      tracker.set_template(f.frame, roi);
    } catch (const InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message({0, 0, 0, 0}).find("at least 8x8"), std::string::npos);
  EXPECT_NE(message({300, 10, 40, 40}).find("not inside the 320x256 frame"), std::string::npos);
  EXPECT_NE(message({-1, 10, 40, 40}).find("ROI x -1, y 10, 40x40"), std::string::npos);
  // A flat patch: no contrast to follow.
  imaging::Frame flat = f.frame;
  std::fill(flat.pixels.begin(), flat.pixels.end(), std::uint16_t{1000});
  EXPECT_THROW(tracker.set_template(flat, {10, 10, 40, 40}), InvalidInput);
  EXPECT_THROW(tracker.track(f.frame), InvalidInput) << "no template yet";
  tracker.set_template(f.frame, {100, 80, 64, 64});
  EXPECT_THROW(tracker.track_near(f.frame, std::nan(""), 10.0), InvalidInput);
  TrackerParams bad;
  bad.ecc_blur_px = 4;
  EXPECT_THROW(TemplateTracker{bad}, InvalidParams);
  TrackerParams negative;
  negative.ecc_highpass_px = -1.0;
  EXPECT_THROW(TemplateTracker{negative}, InvalidParams);
}

}  // namespace
}  // namespace mc::vision
