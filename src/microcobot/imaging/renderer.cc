#include "microcobot/imaging/renderer.h"

#include <algorithm>
#include <cmath>

#include "microcobot/imaging/polygon_coverage.h"
#include "microcobot/imaging/substrate_texture.h"

namespace mc::imaging {

namespace {

constexpr int kMargin = 32;  // substrate texture beyond the image (px), for its blur
// An inclined finger: heights along its length, in segments doubling in length from the tip, so
// that the tip (what the microscope focuses on) is drawn at its own height: 2 mm at a rise of 0.5
// puts the first segment within 0.13 um of the tip's height (a depth-from-focus of the tips reads
// the first segment's mean height: with 8 segments it read 1.9 um high).
constexpr int kFingerSegments = 12;
constexpr double kGroupRatio = 1.15;     // layers whose blurs are within 15 % share one blur
constexpr double kDecimateFrom = 6.0;    // sigma [px] from which a group is blurred on a coarser grid
constexpr double kBeadDiffuse = 0.15;    // a bead's surface outside the specular cap: diffuse part
constexpr double kFingerOutline = 0.08;  // an outline's radiance relative to the finger's face
constexpr int kMaxMotionSamples = 64;

// Segment k of a finger: from start_m to start_m + length_m along the bar, from the tip.
struct FingerSpan {
  double start_m, length_m;
};
FingerSpan finger_span(const Finger& f, int k) {
  const double first = f.length_m / static_cast<double>((1 << kFingerSegments) - 1);
  return {first * ((1 << k) - 1), first * (1 << k)};
}

double overlap(double a0, double a1, double b0, double b1) {
  return std::max(0.0, std::min(a1, b1) - std::max(a0, b0));
}

double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

}  // namespace

using Kind = detail::LayerKind;

Renderer::Renderer(const CameraParams& camera)
    : camera_((camera.validate(), camera)),
      figures_(optics_figures(camera.objective, camera.sensor)),
      psf_(camera.objective),
      sensor_(camera.sensor),
      width_(camera.sensor.width_px),
      height_(camera.sensor.height_px),
      pixel_m_(camera.pixel_size_m()) {
  image_.resize(static_cast<std::size_t>(width_) * height_);
}

CameraControls Renderer::default_controls() const {
  return {0.0, camera_.sensor.exposure_s, camera_.sensor.gain};
}

void Renderer::render_substrate(const Substrate& s, double sigma_px) {
  const bool same_texture = texture_valid_ && s.reflectance == texture_of_.reflectance &&
                            s.texture_contrast == texture_of_.texture_contrast &&
                            s.texture_grain_m == texture_of_.texture_grain_m &&
                            s.texture_octaves == texture_of_.texture_octaves &&
                            s.texture_seed == texture_of_.texture_seed;
  const int tw = width_ + 2 * kMargin, th = height_ + 2 * kMargin;
  if (!same_texture) {
    texture_.resize(static_cast<std::size_t>(tw) * th);
    const double base = s.reflectance;
    for (int i = 0; i < th; ++i) {
      const double y = camera_.view_center_y_m + (0.5 * (height_ - 1) - (i - kMargin)) * pixel_m_;
      for (int j = 0; j < tw; ++j) {
        const double x = camera_.view_center_x_m + ((j - kMargin) - 0.5 * (width_ - 1)) * pixel_m_;
        texture_[static_cast<std::size_t>(i) * tw + j] =
            static_cast<float>(std::max(0.0, base * (1.0 + substrate_texture(s, x, y, pixel_m_))));
      }
    }
    texture_of_ = s;
    texture_valid_ = true;
    substrate_sigma_px_ = -1.0;
  }
  if (substrate_sigma_px_ != sigma_px) {
    substrate_ = texture_;
    gaussian_blur(substrate_.data(), tw, th, tw, sigma_px, scratch_);
    substrate_sigma_px_ = sigma_px;
  }
  for (int i = 0; i < height_; ++i) {
    std::copy_n(substrate_.begin() + static_cast<std::ptrdiff_t>(i + kMargin) * tw + kMargin, width_,
                image_.begin() + static_cast<std::ptrdiff_t>(i) * width_);
  }
}

const std::vector<float>& Renderer::render_expected(const SceneSnapshot& scene, const CameraControls& c) {
  const auto sigma_px = [&](double z_m) { return psf_.sigma_m(z_m - c.focus_z_m) / pixel_m_; };
  render_substrate(scene.substrate, sigma_px(0.0));

  layers_.clear();
  for (std::size_t i = 0; i < scene.holes.size(); ++i)
    layers_.push_back({Kind::kHole, i, 0, 0.0, sigma_px(0.0), false});
  for (std::size_t i = 0; i < scene.parts.size(); ++i) {
    const double z = scene.parts[i].z_top_m;
    layers_.push_back({Kind::kPart, i, 0, z, sigma_px(z), false});
  }
  for (std::size_t i = 0; i < scene.beads.size(); ++i) {
    const Bead& b = scene.beads[i];
    layers_.push_back({Kind::kBead, i, 0, b.z_m, sigma_px(b.z_m), b.radius_m < pixel_m_});
  }
  // A finger is laid over the scene at its tip's height (what is under its body higher up is
  // lower than the tip in this scene: the substrate, parts, beads on the substrate).
  for (std::size_t i = 0; i < scene.fingers.size(); ++i)
    layers_.push_back(
        {Kind::kFinger, i, -1, scene.fingers[i].z_tip_m, sigma_px(scene.fingers[i].z_tip_m), false});
  std::stable_sort(layers_.begin(), layers_.end(),
                   [](const Layer& a, const Layer& b) { return a.z_m < b.z_m; });
  const auto alone = [](const Layer& l) { return l.analytic || l.whole_finger(); };
  for (std::size_t b = 0; b < layers_.size();) {
    if (layers_[b].whole_finger()) {
      composite_finger(scene, layers_[b].index, c.focus_z_m, c.exposure_s);
      ++b;
      continue;
    }
    std::size_t e = b + 1;
    double lo = layers_[b].sigma_px, hi = lo;
    while (!alone(layers_[b]) && e < layers_.size() && !alone(layers_[e])) {
      const double s = layers_[e].sigma_px;
      if (std::max(hi, s) > kGroupRatio * std::min(lo, s)) break;
      lo = std::min(lo, s);
      hi = std::max(hi, s);
      ++e;
    }
    composite_group(scene, layers_, b, e, c.exposure_s);
    b = e;
  }
  const float scale = static_cast<float>(camera_.illumination.electrons_per_s * c.exposure_s);
  for (float& v : image_) v *= scale;
  return image_;
}

void Renderer::render(const SceneSnapshot& scene, const CameraControls& c, std::uint64_t seed,
                      std::uint64_t frame_index, Frame& out) {
  render_expected(scene, c);
  sensor_.read_out(image_, SensorControls{c.exposure_s, c.gain}, seed, frame_index, true, out);
}

namespace {

// An object's top face in stage metres: a box (with an optional outline: a dark border `inset`
// wide on its x sides and, for a finger's tip segment, at its low-y end), a disc, or a bead.
struct Shape {
  enum Type { kBox, kDisc, kSphere } type = kBox;
  double x = 0, y = 0;       // centre
  double hx = 0, hy = 0;     // half sides (box) or radius in hx (disc, sphere)
  double radiance = 0;       // face
  double edge_radiance = 0;  // outline
  double inset_x = 0, inset_low_y = 0;
  double cap = 0;  // sphere: fraction of the radius inside the bright cap
  double cap_radiance = 0, rim_radiance = 0;
  double vx = 0, vy = 0;
  double angle = 0;  // a box turned counter-clockwise as seen from the top [rad]
  // Half extents of the (turned) box's axis-aligned bounding box.
  double ex() const {
    return type == kBox ? std::abs(std::cos(angle)) * hx + std::abs(std::sin(angle)) * hy : hx;
  }
  double ey() const {
    return type == kBox ? std::abs(std::sin(angle)) * hx + std::abs(std::cos(angle)) * hy : hy;
  }
};

Shape bead_shape(const Bead& b, bool transmitted, double cap) {
  Shape s;
  s.type = Shape::kSphere;
  s.x = b.x_m, s.y = b.y_m, s.hx = s.hy = b.radius_m;
  // Reflected: the cap whose slope sends light back within the objective's cone; the rim
  // keeps a diffuse part. Transmitted: a ball lens, bright centre, dark ring.
  s.cap = transmitted ? 0.5 : cap;
  s.cap_radiance = transmitted ? 1.0 : b.reflectance;
  s.rim_radiance = transmitted ? 0.1 : kBeadDiffuse * b.reflectance;
  s.vx = b.vx_m_s, s.vy = b.vy_m_s;
  return s;
}

// The shape of object `i` of `kind`; for a finger, its segment `segment` (composite_finger).
Shape shape_of(const SceneSnapshot& scene, Kind kind, std::size_t i, int segment, bool transmitted,
               double cap) {
  Shape s;
  switch (kind) {
    case Kind::kHole: {
      const Hole& h = scene.holes[i];
      s.type = h.disc ? Shape::kDisc : Shape::kBox;
      s.x = h.x_m, s.y = h.y_m, s.hx = 0.5 * h.size_x_m, s.hy = h.disc ? s.hx : 0.5 * h.size_y_m;
      s.radiance = s.edge_radiance = transmitted ? 1.0 : h.bottom_reflectance;
      s.angle = h.disc ? 0.0 : h.angle_rad;
      break;
    }
    case Kind::kPart: {
      const Part& p = scene.parts[i];
      s.type = p.disc ? Shape::kDisc : Shape::kBox;
      s.x = p.x_m, s.y = p.y_m, s.hx = 0.5 * p.size_x_m, s.hy = p.disc ? s.hx : 0.5 * p.size_y_m;
      s.radiance = s.edge_radiance = transmitted ? 0.0 : p.reflectance;
      s.vx = p.vx_m_s, s.vy = p.vy_m_s;
      s.angle = p.disc ? 0.0 : p.angle_rad;
      break;
    }
    case Kind::kBead:
      return bead_shape(scene.beads[i], transmitted, cap);
    case Kind::kFinger: {
      const Finger& f = scene.fingers[i];
      const FingerSpan span = finger_span(f, segment);
      const double len = span.length_m;
      s.type = Shape::kBox;
      s.x = f.tip_x_m, s.y = f.tip_y_m + span.start_m + 0.5 * len;
      if (f.angle_rad != 0.0) {  // turned about the pivot (the gripper's rotary axis)
        const double c = std::cos(f.angle_rad), sn = std::sin(f.angle_rad);
        const double dx = s.x - f.pivot_x_m, dy = s.y - f.pivot_y_m;
        s.x = f.pivot_x_m + c * dx - sn * dy;
        s.y = f.pivot_y_m + sn * dx + c * dy;
        s.angle = f.angle_rad;
      }
      s.hx = 0.5 * f.width_m, s.hy = 0.5 * len;
      s.radiance = transmitted ? 0.0 : f.reflectance;
      s.edge_radiance = transmitted ? 0.0 : kFingerOutline * f.reflectance;
      s.inset_x = std::min(f.outline_m, s.hx);
      // The end's outline spans outline_m from the tip, over as many of the short first segments.
      s.inset_low_y = std::clamp(f.outline_m - span.start_m, 0.0, len);
      s.vx = f.vx_m_s, s.vy = f.vy_m_s;
      break;
    }
  }
  return s;
}

// A sphere's mean radiance over its disc.
double sphere_mean(const Shape& s) {
  return s.cap * s.cap * s.cap_radiance + (1 - s.cap * s.cap) * s.rim_radiance;
}

}  // namespace

void Renderer::draw_point_bead(const Bead& bead, double sigma_px, double exposure_s) {
  // A bead smaller than a pixel: its image is the PSF (widened by the disc's own second moment,
  // R^2/4 per axis) integrated exactly over each pixel, times its flux; drawn "over" the image
  // with that blurred coverage. Motion: the mean of positions along its path.
  const double theta = std::asin(camera_.objective.numerical_aperture / camera_.objective.immersion_index);
  const Shape s = bead_shape(bead, camera_.illumination.transmitted(), std::sin(0.5 * theta));
  const double r_px = bead.radius_m / pixel_m_;
  const double sig = std::sqrt(sigma_px * sigma_px + 0.25 * r_px * r_px);
  const double area = M_PI * r_px * r_px, rad = sphere_mean(s);
  const double du = s.vx * exposure_s / pixel_m_, dv = -s.vy * exposure_s / pixel_m_;
  const int samples = std::clamp(static_cast<int>(std::ceil(std::hypot(du, dv))) + 1, 1, kMaxMotionSamples);
  const double reach = 5.0 * sig + 1.0 + 0.5 * std::max(std::abs(du), std::abs(dv));
  const double u = u_of_x(bead.x_m), v = v_of_y(bead.y_m);
  const int j0 = std::max(0, static_cast<int>(std::floor(u - reach))),
            j1 = std::min(width_ - 1, static_cast<int>(std::ceil(u + reach)));
  const int i0 = std::max(0, static_cast<int>(std::floor(v - reach))),
            i1 = std::min(height_ - 1, static_cast<int>(std::ceil(v + reach)));
  if (j0 > j1 || i0 > i1) return;
  const int w = j1 - j0 + 1, h = i1 - i0 + 1;
  obj_cover_.assign(static_cast<std::size_t>(w) * h, 0.0f);
  std::vector<float>& gx = obj_premult_;  // per-sample separable factors
  gx.resize(static_cast<std::size_t>(w + h));
  for (int k = 0; k < samples; ++k) {
    const double t = samples == 1 ? 0.0 : static_cast<double>(k) / (samples - 1) - 0.5;
    const double uc = u + t * du, vc = v + t * dv;
    for (int j = 0; j < w; ++j)
      gx[j] =
          static_cast<float>(normal_cdf((j0 + j + 0.5 - uc) / sig) - normal_cdf((j0 + j - 0.5 - uc) / sig));
    for (int i = 0; i < h; ++i)
      gx[w + i] =
          static_cast<float>(normal_cdf((i0 + i + 0.5 - vc) / sig) - normal_cdf((i0 + i - 0.5 - vc) / sig));
    const float a = static_cast<float>(area / samples);
    for (int i = 0; i < h; ++i)
      for (int j = 0; j < w; ++j) obj_cover_[static_cast<std::size_t>(i) * w + j] += a * gx[w + i] * gx[j];
  }
  for (int i = 0; i < h; ++i) {
    float* row = &image_[static_cast<std::size_t>(i0 + i) * width_ + j0];
    for (int j = 0; j < w; ++j) {
      const float a = std::min(1.0f, obj_cover_[static_cast<std::size_t>(i) * w + j]);
      row[j] = row[j] * (1.0f - a) + static_cast<float>(rad) * a;
    }
  }
}

void Renderer::composite_finger(const SceneSnapshot& scene, std::size_t index, double focus_z_m,
                                double exposure_s) {
  // Each segment at the blur of its own height, their coverages and radiances summed: the
  // segments partition the finger, so where two meet in a pixel their coverages add up to the
  // finger's, whatever their blurs (laid one over the other, a + b - ab, they drew a dark seam),
  // and the blur along the finger changes with the focus continuously (grouped by blur, a
  // segment joining its neighbour's group changed the tip's drawn blur in one step: the tips'
  // sharpness against focus had steps, docs/benchmarks.md "Autofocus").
  const Finger& f = scene.fingers[index];
  finger_layers_.clear();
  for (int k = 0; k < kFingerSegments; ++k) {
    const FingerSpan span = finger_span(f, k);
    const double z = f.z_tip_m + f.rise * (span.start_m + 0.5 * span.length_m);
    finger_layers_.push_back({Kind::kFinger, index, k, z, psf_.sigma_m(z - focus_z_m) / pixel_m_, false});
  }
  const std::size_t n = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  if (finger_cover_.size() != n) {
    finger_cover_.assign(n, 0.0f);
    finger_premult_.assign(n, 0.0f);
  }
  canvas_i0_ = height_, canvas_i1_ = -1, canvas_j0_ = width_, canvas_j1_ = -1;
  for (std::size_t k = 0; k < finger_layers_.size(); ++k)
    composite_group(scene, finger_layers_, k, k + 1, exposure_s, true);
  for (int i = canvas_i0_; i <= canvas_i1_; ++i) {
    const std::size_t row = static_cast<std::size_t>(i) * width_;
    for (int j = canvas_j0_; j <= canvas_j1_; ++j) {
      float& a = finger_cover_[row + j];
      float& p = finger_premult_[row + j];
      if (a > 1.0f) {  // blurs of different widths can overlap a little beyond full cover
        p /= a;
        a = 1.0f;
      }
      image_[row + j] = image_[row + j] * (1.0f - a) + p;
      a = p = 0.0f;  // the canvas clean for the next finger
    }
  }
}

void Renderer::composite_group(const SceneSnapshot& scene, const std::vector<Layer>& layers,
                               std::size_t begin, std::size_t end, double exposure_s, bool to_finger) {
  if (layers[begin].analytic) {
    draw_point_bead(scene.beads[layers[begin].index], layers[begin].sigma_px, exposure_s);
    return;
  }
  const bool transmitted = camera_.illumination.transmitted();
  const double cap =
      std::sin(0.5 * std::asin(camera_.objective.numerical_aperture / camera_.objective.immersion_index));
  double sigma = 0.0;
  for (std::size_t l = begin; l < end; ++l) sigma += layers[l].sigma_px;
  sigma /= static_cast<double>(end - begin);

  // The group's extent (px), with its motion and a blur margin, within the image + margin.
  const double pad = 4.0 * sigma + 2.0;
  double u_lo = 1e300, u_hi = -1e300, v_lo = 1e300, v_hi = -1e300;
  for (std::size_t l = begin; l < end; ++l) {
    const Shape s = shape_of(scene, layers[l].kind, layers[l].index, layers[l].segment, transmitted, cap);
    const double mx = std::abs(s.vx) * exposure_s * 0.5, my = std::abs(s.vy) * exposure_s * 0.5;
    u_lo = std::min(u_lo, u_of_x(s.x - s.ex() - mx));
    u_hi = std::max(u_hi, u_of_x(s.x + s.ex() + mx));
    v_lo = std::min(v_lo, v_of_y(s.y + s.ey() + my));
    v_hi = std::max(v_hi, v_of_y(s.y - s.ey() - my));
  }
  const int bx0 = std::max(static_cast<int>(std::floor(u_lo - pad)), -static_cast<int>(pad));
  const int bx1 = std::min(static_cast<int>(std::ceil(u_hi + pad)), width_ - 1 + static_cast<int>(pad));
  const int by0 = std::max(static_cast<int>(std::floor(v_lo - pad)), -static_cast<int>(pad));
  const int by1 = std::min(static_cast<int>(std::ceil(v_hi + pad)), height_ - 1 + static_cast<int>(pad));
  if (bx0 > bx1 || by0 > by1 || bx1 < 0 || by1 < 0 || bx0 >= width_ || by0 >= height_) return;
  // Wide blurs on a grid of f x f pixel cells: the cells' area average and the bilinear
  // upsampling add (1/12 + 1/6) f^2 of variance, taken off the blur.
  const int f = sigma >= kDecimateFrom ? static_cast<int>(sigma / 3.0) : 1;
  const int nx = (bx1 - bx0 + f) / f, ny = (by1 - by0 + f) / f;
  const double gx0 = bx0 - 0.5, gy0 = by0 - 0.5;
  cover_.assign(static_cast<std::size_t>(nx) * ny, 0.0f);
  premult_.assign(cover_.size(), 0.0f);
  obj_cover_.resize(cover_.size());
  obj_premult_.resize(cover_.size());

  for (std::size_t l = begin; l < end; ++l) {
    const Shape s = shape_of(scene, layers[l].kind, layers[l].index, layers[l].segment, transmitted, cap);
    const double du = s.vx * exposure_s / pixel_m_, dv = -s.vy * exposure_s / pixel_m_;
    const int samples =
        std::clamp(static_cast<int>(std::ceil(std::hypot(du, dv) / f)) + 1, 1, kMaxMotionSamples);
    // The object's cells (all samples).
    const double hu = s.ex() / pixel_m_, hv = s.ey() / pixel_m_;
    const double uc0 = u_of_x(s.x), vc0 = v_of_y(s.y);
    const int cx0 = std::max(0, static_cast<int>(std::floor((uc0 - hu - 0.5 * std::abs(du) - gx0) / f)) - 1);
    const int cx1 =
        std::min(nx - 1, static_cast<int>(std::ceil((uc0 + hu + 0.5 * std::abs(du) - gx0) / f)) + 1);
    const int cy0 = std::max(0, static_cast<int>(std::floor((vc0 - hv - 0.5 * std::abs(dv) - gy0) / f)) - 1);
    const int cy1 =
        std::min(ny - 1, static_cast<int>(std::ceil((vc0 + hv + 0.5 * std::abs(dv) - gy0) / f)) + 1);
    if (cx0 > cx1 || cy0 > cy1) continue;
    for (int cy = cy0; cy <= cy1; ++cy) {
      std::fill_n(&obj_cover_[static_cast<std::size_t>(cy) * nx + cx0], cx1 - cx0 + 1, 0.0f);
      std::fill_n(&obj_premult_[static_cast<std::size_t>(cy) * nx + cx0], cx1 - cx0 + 1, 0.0f);
    }
    const float w = 1.0f / static_cast<float>(samples);
    for (int k = 0; k < samples; ++k) {
      const double t = samples == 1 ? 0.0 : static_cast<double>(k) / (samples - 1) - 0.5;
      // Centre in cell coordinates; sizes in cells.
      const double cu = (uc0 + t * du - gx0) / f, cv = (vc0 + t * dv - gy0) / f;
      const double ax = hu / f, ay = hv / f;
      for (int cy = cy0; cy <= cy1; ++cy) {
        for (int cx = cx0; cx <= cx1; ++cx) {
          double a = 0.0, p = 0.0;
          if (s.type == Shape::kBox && s.angle != 0.0) {
            // Turned: the exact area of the polygon in the cell. Rows go down, so the
            // counter-clockwise turn seen from the top is clockwise in the cells' frame.
            const double cs = std::cos(s.angle), sn = -std::sin(s.angle);
            const RotatedRect r{cu, cv, s.hx / pixel_m_ / f, s.hy / pixel_m_ / f, cs, sn};
            a = cell_coverage(r, cx, cy);
            p = a * s.radiance;
            if (a > 0.0 && (s.inset_x > 0.0 || s.inset_low_y > 0.0)) {
              // The outline (a turned finger): the inner box leaves inset_x each side and
              // inset_low_y at the low-y end, its centre moved up the box's own y by half that.
              const double ix = s.inset_x / pixel_m_ / f, iy = s.inset_low_y / pixel_m_ / f;
              // The box's own +y in the cells' frame (rows down): (-sin, -cos) of the turn.
              const RotatedRect in{cu - 0.5 * iy * std::sin(s.angle),
                                   cv - 0.5 * iy * std::cos(s.angle),
                                   std::max(0.0, r.a - ix),
                                   std::max(0.0, r.b - 0.5 * iy),
                                   cs,
                                   sn};
              const double inner = cell_coverage(in, cx, cy);
              p = s.edge_radiance * (a - inner) + s.radiance * inner;
            }
          } else if (s.type == Shape::kBox) {
            const double ox = overlap(cx, cx + 1.0, cu - ax, cu + ax);
            const double oy = overlap(cy, cy + 1.0, cv - ay, cv + ay);
            a = ox * oy;
            if (a > 0.0) {
              const double ix = s.inset_x / pixel_m_ / f, iy = s.inset_low_y / pixel_m_ / f;
              // The low-y end is the image's bottom (rows grow downward): cv + ay.
              const double inner = overlap(cx, cx + 1.0, cu - ax + ix, cu + ax - ix) *
                                   overlap(cy, cy + 1.0, cv - ay, cv + ay - iy);
              p = s.edge_radiance * (a - inner) + s.radiance * inner;
            }
          } else {
            const double dx = cx + 0.5 - cu, dy = cy + 0.5 - cv, r = ax;
            if (r < 1.0) {
              // Smaller than a cell: area-conserving bilinear splat.
              a = M_PI * r * r * std::max(0.0, 1.0 - std::abs(dx)) * std::max(0.0, 1.0 - std::abs(dy));
              p = a * (s.type == Shape::kSphere ? sphere_mean(s) : s.radiance);
            } else {
              const double d = std::hypot(dx, dy);
              a = std::clamp(r - d + 0.5, 0.0, 1.0);
              const double rad =
                  s.type == Shape::kSphere ? (d <= s.cap * r ? s.cap_radiance : s.rim_radiance) : s.radiance;
              p = a * rad;
            }
          }
          obj_cover_[static_cast<std::size_t>(cy) * nx + cx] += w * static_cast<float>(a);
          obj_premult_[static_cast<std::size_t>(cy) * nx + cx] += w * static_cast<float>(p);
        }
      }
    }
    // Over what the group already holds (this object is higher).
    for (int cy = cy0; cy <= cy1; ++cy) {
      for (int cx = cx0; cx <= cx1; ++cx) {
        const std::size_t q = static_cast<std::size_t>(cy) * nx + cx;
        const float a = std::min(1.0f, obj_cover_[q]);
        premult_[q] = obj_premult_[q] + premult_[q] * (1.0f - a);
        cover_[q] = a + cover_[q] * (1.0f - a);
      }
    }
  }

  // Area coverage already integrates the pixel (1/12 px^2), the integrated kernel adds it again.
  const double var = sigma * sigma - (f > 1 ? 0.25 * f * f : 1.0 / 12.0);
  const double sigma_cells = std::sqrt(std::max(var, 0.0)) / f;
  gaussian_blur(cover_.data(), nx, ny, nx, sigma_cells, scratch_);
  gaussian_blur(premult_.data(), nx, ny, nx, sigma_cells, scratch_);

  const int j0 = std::max(0, bx0), j1 = std::min(width_ - 1, bx1);
  const int i0 = std::max(0, by0), i1 = std::min(height_ - 1, by1);
  if (to_finger) {
    canvas_i0_ = std::min(canvas_i0_, i0), canvas_i1_ = std::max(canvas_i1_, i1);
    canvas_j0_ = std::min(canvas_j0_, j0), canvas_j1_ = std::max(canvas_j1_, j1);
  }
  // Over the image, or added to the finger's canvas.
  const auto lay = [&](int i, int j, float a, float p) {
    const std::size_t q = static_cast<std::size_t>(i) * width_ + j;
    if (to_finger) {
      finger_cover_[q] += a;
      finger_premult_[q] += p;
    } else {
      image_[q] = image_[q] * (1.0f - a) + p;
    }
  };
  if (f > 1) {
    // Column positions in the cell grid, once per group (x0 + 1 always valid: one spare cell).
    col_x0_.resize(static_cast<std::size_t>(j1 - j0 + 1));
    col_tx_.resize(col_x0_.size());
    row_cover_.assign(static_cast<std::size_t>(nx) + 1, 0.0f);
    row_premult_.assign(static_cast<std::size_t>(nx) + 1, 0.0f);
    for (int j = j0; j <= j1; ++j) {
      const double cxf = std::clamp((j - bx0 + 0.5) / f - 0.5, 0.0, nx - 1.0);
      const int x0 = std::min(static_cast<int>(cxf), std::max(nx - 2, 0));
      col_x0_[j - j0] = x0;
      col_tx_[j - j0] = nx > 1 ? static_cast<float>(cxf - x0) : 0.0f;
    }
  }
  for (int i = i0; i <= i1; ++i) {
    if (f == 1) {
      const float* a = &cover_[static_cast<std::size_t>(i - by0) * nx];
      const float* p = &premult_[static_cast<std::size_t>(i - by0) * nx];
      for (int j = j0; j <= j1; ++j) lay(i, j, a[j - bx0], p[j - bx0]);
      continue;
    }
    const double cyf = std::clamp((i - by0 + 0.5) / f - 0.5, 0.0, ny - 1.0);
    const int y0 = std::min(static_cast<int>(cyf), std::max(ny - 2, 0));
    const int y1 = std::min(y0 + 1, ny - 1);
    const float ty = static_cast<float>(cyf - y0);
    // The group's two cell rows blended once, then each pixel interpolates along x.
    for (int cx = 0; cx < nx; ++cx) {
      const std::size_t q0 = static_cast<std::size_t>(y0) * nx + cx,
                        q1 = static_cast<std::size_t>(y1) * nx + cx;
      row_cover_[cx] = cover_[q0] + ty * (cover_[q1] - cover_[q0]);
      row_premult_[cx] = premult_[q0] + ty * (premult_[q1] - premult_[q0]);
    }
    for (int j = j0; j <= j1; ++j) {
      const int x0 = col_x0_[j - j0];
      const float tx = col_tx_[j - j0];
      const float a = row_cover_[x0] + tx * (row_cover_[x0 + 1] - row_cover_[x0]);
      const float p = row_premult_[x0] + tx * (row_premult_[x0 + 1] - row_premult_[x0]);
      lay(i, j, a, p);
    }
  }
}

}  // namespace mc::imaging
