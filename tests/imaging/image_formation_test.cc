// Image formation measured on rendered images: the in-focus PSF's FWHM, the
// through-focus sharpness curve's width against the depth-of-field formula, the scale, and
// determinism. Small sensors (the physics does not depend on the pixel count) keep them fast.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "microcobot/imaging/renderer.h"

namespace mc::imaging {
namespace {

constexpr double kFwhmPerSigma = 2.3548200450309493;  // 2 sqrt(2 ln 2)

CameraParams small_camera(const std::string& objective, int w = 320, int h = 256) {
  CameraParams c;
  c.objective = objective_by_name(objective);
  c.sensor.width_px = w;
  c.sensor.height_px = h;
  return c;
}

SceneSnapshot dark_flat_scene(double reflectance = 0.02) {
  SceneSnapshot s;
  s.substrate.reflectance = reflectance;
  s.substrate.texture_contrast = 0.0;
  return s;
}

// Sigma [px] of a spot from the second moment of its row-summed profile around `centre`
// (background subtracted), less Sheppard's correction 1/12 for the pixel.
double spot_sigma_px(const std::vector<float>& img, int w, int h, double background, bool along_x) {
  const auto peak = std::max_element(img.begin(), img.end()) - img.begin();
  const int pi = static_cast<int>(peak / w), pj = static_cast<int>(peak % w);
  const int half = 40;
  std::vector<double> profile(2 * half + 1, 0.0);
  for (int i = pi - half; i <= pi + half; ++i)
    for (int j = pj - half; j <= pj + half; ++j) {
      if (i < 0 || j < 0 || i >= h || j >= w) continue;
      profile[along_x ? j - pj + half : i - pi + half] +=
          double(img[static_cast<std::size_t>(i) * w + j]) - background;
    }
  double m0 = 0, m1 = 0, m2 = 0;
  for (int k = 0; k < 2 * half + 1; ++k) {
    m0 += profile[k];
    m1 += profile[k] * k;
    m2 += profile[k] * k * k;
  }
  const double mean = m1 / m0;
  return std::sqrt(m2 / m0 - mean * mean - 1.0 / 12.0);
}

// A sub-resolution bead at every objective: the FWHM of its image is the model's PSF FWHM.
TEST(ImageFormation, InFocusPsfFwhmOfASubResolutionBead) {
  for (const ObjectiveParams& o : objective_table()) {
    Renderer r(small_camera(o.name));
    const double px = r.camera().pixel_size_m();
    SceneSnapshot s = dark_flat_scene(0.0);  // a black ground: the spot's moments free of float rounding
    Bead bead;
    bead.radius_m = 0.2 * px;  // sub-pixel: the exact (pixel-integrated) path
    bead.x_m = 0.37 * px, bead.y_m = -0.21 * px;
    s.beads.push_back(bead);
    const auto& img = r.render_expected(s, r.default_controls());
    const double bg = 0.0;
    for (bool along_x : {true, false}) {
      const double sigma = spot_sigma_px(img, 320, 256, bg, along_x);
      // The bead's own second moment, R^2 / 4, taken off.
      const double psf_sigma_m = std::sqrt(sigma * sigma - 0.25 * 0.04) * px;
      const double fwhm = kFwhmPerSigma * psf_sigma_m;
      std::printf("psf %s %s: measured FWHM %.4f um, model %.4f um, ratio %.4f\n", o.name.c_str(),
                  along_x ? "x" : "y", fwhm * 1e6, r.figures().psf_fwhm_m * 1e6,
                  fwhm / r.figures().psf_fwhm_m);
      EXPECT_NEAR(fwhm / r.figures().psf_fwhm_m, 1.0, 0.05) << o.name << (along_x ? " x" : " y");
    }
  }
}

// The same through the rasterised path: a uniform dot of 1.2 px radius (0.25 um diameter at
// 50x, under the 0.61 um resolution), blurred as any object is.
TEST(ImageFormation, InFocusPsfFwhmThroughTheRasterisedPath) {
  Renderer r(small_camera("50x"));
  const double px = r.camera().pixel_size_m();
  SceneSnapshot s = dark_flat_scene(0.0);
  Part dot;
  dot.disc = true;
  dot.size_x_m = 2.4 * px;
  dot.x_m = 0.3 * px;
  dot.reflectance = 1.0;
  s.parts.push_back(dot);
  const auto& img = r.render_expected(s, r.default_controls());
  const double sigma = spot_sigma_px(img, 320, 256, 0.0, true);
  const double psf_sigma_m = std::sqrt(sigma * sigma - 0.25 * 1.2 * 1.2) * px;
  std::printf("psf 50x rasterised dot: ratio %.4f\n", kFwhmPerSigma * psf_sigma_m / r.figures().psf_fwhm_m);
  EXPECT_NEAR(kFwhmPerSigma * psf_sigma_m / r.figures().psf_fwhm_m, 1.0, 0.05);
}

// Normalised variance var/mean^2 of the image's centre (edges excluded).
double normalised_variance(const std::vector<float>& img, int w, int h) {
  double s = 0, s2 = 0;
  std::size_t n = 0;
  for (int i = 40; i < h - 40; ++i)
    for (int j = 40; j < w - 40; ++j) {
      const auto v = static_cast<double>(img[static_cast<std::size_t>(i) * w + j]);
      s += v, s2 += v * v, ++n;
    }
  const double mean = s / n;
  return (s2 / n - mean * mean) / (mean * mean);
}

// The through-focus sharpness curve of a white texture (grain far below the pixel: one
// independent value per pixel) is as wide as the depth-of-field formula says, at the level the
// formula's two criteria set (docs/concepts/vision.md, "Depth of field": the quarter-wave criterion's
// level on a diffraction-limited curve and the blur-circle-equals-pixel level on a
// pixel-limited one, averaged).
TEST(ImageFormation, ThroughFocusSharpnessWidthMatchesTheDepthOfField) {
  for (const ObjectiveParams& o : objective_table()) {
    Renderer r(small_camera(o.name));
    SceneSnapshot s;
    s.substrate.reflectance = 0.5;
    s.substrate.texture_contrast = 0.2;
    s.substrate.texture_grain_m = 1e-9;
    s.substrate.texture_octaves = 1;
    const double level = 0.5 * (r.psf().relative_sharpness(0.25) + 16.0 / 28.0);
    CameraControls c = r.default_controls();
    const double f0 = normalised_variance(r.render_expected(s, c), 320, 256);
    const double dof = r.figures().dof_m, step = dof / 200.0;
    double edges[2] = {0, 0};
    for (int side = 0; side < 2; ++side) {
      const double sign = side == 0 ? 1.0 : -1.0;
      double prev = 1.0;
      for (int k = 1; k < 400; ++k) {
        c.focus_z_m = sign * k * step;
        const double f = normalised_variance(r.render_expected(s, c), 320, 256) / f0;
        if (f < level) {
          edges[side] = sign * step * (k - 1 + (prev - level) / (prev - f));
          break;
        }
        prev = f;
      }
    }
    const double width = edges[0] - edges[1];
    std::printf("dof %s: level %.3f, width %.3f um, formula %.3f um, ratio %.4f\n", o.name.c_str(), level,
                width * 1e6, dof * 1e6, width / dof);
    // At 2x the model's curve is 10.1 % narrower than the formula (docs/concepts/vision.md: the formula adds
    // its two criteria linearly, the blurs add in quadrature; largest where both are comparable
    // in pixels): the one objective held to 11 %.
    EXPECT_NEAR(width / dof, 1.0, o.name == "2x" ? 0.11 : 0.10)
        << o.name << ": width " << width * 1e6 << " um, DOF " << dof * 1e6 << " um";
  }
}

// Two dots a known stage distance apart: their sub-pixel centroids are pixel_pitch / M apart per
// metre... i.e. the scale is the objective's, within 0.1 %, on a noisy 12-bit frame.
TEST(ImageFormation, ScaleIsPixelPitchOverMagnification) {
  for (const ObjectiveParams& o : objective_table()) {
    CameraParams cam = small_camera(o.name, 640, 512);
    Renderer r(cam);
    const double px = r.camera().pixel_size_m();
    const double d = 0.6 * 640 * px;  // 0.6 of the field's width, along x; 0.5 of its height along y
    const double dy = 0.5 * 512 * px;
    SceneSnapshot s = dark_flat_scene();
    s.substrate.reflectance = 0.1;
    for (const auto& [x, y] :
         {std::pair{-0.5 * d, 0.3 * dy}, std::pair{0.5 * d, 0.3 * dy}, std::pair{-0.5 * d, -0.7 * dy}}) {
      Part dot;
      dot.disc = true;
      dot.size_x_m = 12.3 * px;
      dot.x_m = x + 0.137 * px, dot.y_m = y - 0.291 * px;
      dot.z_top_m = 0.0;
      s.parts.push_back(dot);
    }
    Frame f;
    r.render(s, r.default_controls(), 7, 0, f);
    const auto centroid = [&](double x_m, double y_m) {
      const double u = r.u_of_x(x_m), v = r.v_of_y(y_m);
      double bg = 0;
      int nb = 0;
      for (int j = -30; j <= 30; ++j)
        bg += f.pixels[static_cast<std::size_t>(std::lround(v) - 25) * 640 + std::lround(u) + j], ++nb;
      bg /= nb;
      double m0 = 0, mu = 0, mv = 0;
      for (int i = -15; i <= 15; ++i)
        for (int j = -15; j <= 15; ++j) {
          const long ii = std::lround(v) + i, jj = std::lround(u) + j;
          const double w = f.pixels[static_cast<std::size_t>(ii) * 640 + jj] - bg;
          m0 += w, mu += w * jj, mv += w * ii;
        }
      return std::pair{mu / m0, mv / m0};
    };
    const auto a = centroid(s.parts[0].x_m, s.parts[0].y_m), b = centroid(s.parts[1].x_m, s.parts[1].y_m),
               c = centroid(s.parts[2].x_m, s.parts[2].y_m);
    const double scale_x = d / (b.first - a.first), scale_y = dy / (c.second - a.second);
    const double expected = cam.sensor.pixel_pitch_m / cam.objective.magnification;
    std::printf("scale %s: x %.6f, y %.6f of pitch/M\n", o.name.c_str(), scale_x / expected,
                scale_y / expected);
    EXPECT_NEAR(scale_x / expected, 1.0, 1e-3) << o.name;
    EXPECT_NEAR(scale_y / expected, 1.0, 1e-3) << o.name;
  }
}

TEST(ImageFormation, DeterministicFromSeedAndFrameIndex) {
  CameraParams cam = small_camera("10x");
  SceneSnapshot s;
  Part p;
  p.size_x_m = p.size_y_m = 100e-6;
  p.z_top_m = 30e-6;
  p.vx_m_s = 2e-3;
  s.parts.push_back(p);
  Renderer a(cam), b(cam);
  Frame f1, f2, f3, other;
  a.render(s, a.default_controls(), 42, 3, f1);
  b.render(s, b.default_controls(), 42, 0, other);  // b renders another frame first
  b.render(s, b.default_controls(), 42, 3, f2);
  a.render(s, a.default_controls(), 43, 3, f3);
  EXPECT_EQ(f1.pixels, f2.pixels);
  EXPECT_NE(f1.pixels, f3.pixels);
  EXPECT_NE(f1.pixels, other.pixels);
}

// Defocus blurs, focus sharpens: a part's edge is steeper in focus than 3 DOF away.
// An inclined finger is drawn in segments (their heights rise along it); those sharing a blur
// are one face: along the finger, near its tip and in focus, the optical image has no seam (a dark
// line where two segments, drawn one over the other, share a pixel: a + b - ab of it covered
// instead of a + b), whichever way the finger rises and wherever its segments' boundaries fall
// in the pixels.
TEST(ImageFormation, AnInclinedFingersFaceHasNoSeamBetweenItsSegments) {
  Renderer r(small_camera("5x"));
  CameraControls c = r.default_controls();
  for (const double rise : {0.5, -0.5, 0.0}) {
    for (const double shift_px : {0.0, 0.3, 0.55, 0.8}) {
      SceneSnapshot s = dark_flat_scene(0.3);
      Finger f;
      f.tip_y_m = -60e-6 + shift_px * r.camera().pixel_size_m();
      f.z_tip_m = 100e-6;
      f.rise = rise;
      s.fingers.push_back(f);
      c.focus_z_m = f.z_tip_m;
      const std::vector<float>& img = r.render_expected(s, c);
      const int w = r.camera().sensor.width_px;
      const int j = static_cast<int>(std::lround(r.u_of_x(f.tip_x_m)));  // the face's centre line
      // From 6 um up the finger (past the end's 4 um dark outline) to 17 um (segment boundaries
      // at 7.3 and 15.1 um from the tip), within the depth of field: one blur group. (Where two groups
      // meet, farther up, their layers still darken the face a little: the layered-defocus
      // approximation, docs/concepts/vision.md.)
      const int i_lo = static_cast<int>(std::ceil(r.v_of_y(f.tip_y_m + 17e-6)));
      const int i_hi = static_cast<int>(std::floor(r.v_of_y(f.tip_y_m + 6e-6)));
      double worst = 0.0;
      for (int i = i_lo + 1; i < i_hi; ++i) {
        const auto at = [&](int row) { return double(img[static_cast<std::size_t>(row) * w + j]); };
        worst = std::max(worst, std::abs(at(i) - 0.5 * (at(i - 1) + at(i + 1))) / at(i));
      }
      // 0.8 % is the end outline's blurred tail at 6 um; the segments drawn one over the other
      // gave 2.3-2.7 %.
      EXPECT_LT(worst, 0.02) << "rise " << rise << ", shift " << shift_px << " px: a seam";
    }
  }
}

TEST(ImageFormation, DefocusSoftensAnEdgeAndMotionSmearsIt) {
  Renderer r(small_camera("20x"));
  SceneSnapshot s = dark_flat_scene();
  Part p;
  p.size_x_m = p.size_y_m = 40e-6;
  p.z_top_m = 10e-6;
  s.parts.push_back(p);
  CameraControls c = r.default_controls();
  const auto edge_slope = [&](const std::vector<float>& img) {
    double best = 0;
    for (int j = 1; j < 320; ++j)
      best = std::max(best, std::abs(double(img[128 * 320 + j]) - double(img[128 * 320 + j - 1])));
    return best;
  };
  c.focus_z_m = 10e-6;
  const double sharp = edge_slope(r.render_expected(s, c));
  c.focus_z_m = 10e-6 + 3 * r.figures().dof_m;
  const double soft = edge_slope(r.render_expected(s, c));
  EXPECT_GT(sharp, 3 * soft);
  c.focus_z_m = 10e-6;
  s.parts[0].vx_m_s = 2e-3;  // 20 um over the 10 ms exposure: ~75 px of smear along x
  const double moving = edge_slope(r.render_expected(s, c));
  EXPECT_GT(sharp, 10 * moving);
}

}  // namespace
}  // namespace mc::imaging
