#include "microcobot/vision/affine_calibration.h"

#include <cmath>
#include <string>

#include "microcobot/core/error.h"

namespace mc::vision {

AffineFigures affine_figures(const AffineMap& map) {
  Eigen::Matrix2d a = map.A;
  a.row(1) *= -1.0;  // rows down -> y up
  const Eigen::Vector2d ex = a.col(0), ey = a.col(1);
  AffineFigures f;
  f.um_per_px_x = 1e6 / ex.norm();
  f.um_per_px_y = 1e6 / ey.norm();
  f.rotation_rad = std::atan2(ex.y(), ex.x());
  const double cross = ex.x() * ey.y() - ex.y() * ey.x();
  f.mirrored = cross < 0.0;
  // The angle from x to y as seen (positive: counter-clockwise), whose ideal is +-90 degrees.
  const double between = std::atan2(std::abs(cross), ex.dot(ey));
  f.shear_rad = between - M_PI / 2;
  return f;
}

AffineFit fit_affine(std::span<const Eigen::Vector2d> stage_m, std::span<const Eigen::Vector2d> pixel) {
  if (stage_m.size() != pixel.size())
    throw InvalidInput("affine calibration: " + std::to_string(stage_m.size()) + " stage points but " +
                       std::to_string(pixel.size()) + " image points");
  const auto n = static_cast<Eigen::Index>(stage_m.size());
  if (n < 3)
    throw InvalidInput("affine calibration: " + std::to_string(n) +
                       " point(s); an affine map needs at least 3 not on a line");
  // Centred for conditioning: stage points are micrometres apart around millimetres.
  Eigen::Vector2d sc = Eigen::Vector2d::Zero(), pc = Eigen::Vector2d::Zero();
  for (Eigen::Index k = 0; k < n; ++k) {
    if (!stage_m[k].allFinite() || !pixel[k].allFinite())
      throw InvalidInput("affine calibration: point " + std::to_string(k) + " is not finite");
    sc += stage_m[k];
    pc += pixel[k];
  }
  sc /= static_cast<double>(n);
  pc /= static_cast<double>(n);
  Eigen::MatrixX2d s(n, 2), p(n, 2);
  for (Eigen::Index k = 0; k < n; ++k) {
    s.row(k) = (stage_m[k] - sc).transpose();
    p.row(k) = (pixel[k] - pc).transpose();
  }
  const Eigen::JacobiSVD<Eigen::MatrixX2d> svd(s, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::Vector2d sv = svd.singularValues();
  if (!(sv(1) > 1e-9 * sv(0)))
    throw InvalidInput("affine calibration: the stage points lie on a line; the map needs two directions");
  AffineFit fit;
  fit.map.A = svd.solve(p).transpose();  // p^T = A s^T
  fit.map.b = pc - fit.map.A * sc;
  double sum2 = 0.0;
  for (Eigen::Index k = 0; k < n; ++k) {
    const Eigen::Vector2d r = pixel[k] - fit.map.pixel_of(stage_m[k]);
    fit.residuals_px.push_back(r);
    sum2 += r.squaredNorm();
    fit.residual_max_px = std::max(fit.residual_max_px, r.norm());
  }
  fit.residual_rms_px = std::sqrt(sum2 / static_cast<double>(n));
  return fit;
}

void StageCalibration::validate() const {
  require(!objective.empty(), "objective", "must name the objective the calibration was measured with");
  require(px_per_m.size() == 2 && px_per_m[0].size() == 2 && px_per_m[1].size() == 2, "px_per_m",
          "must be a 2 x 2 matrix [[a, b], [c, d]]");
  require(offset_px.size() == 2, "offset_px", "must be two numbers (u, v)");
  for (const auto& row : px_per_m)
    for (double a : row) require(std::isfinite(a), "px_per_m", "must be finite", a);
  for (double b : offset_px) require(std::isfinite(b), "offset_px", "must be finite", b);
  const double det = px_per_m[0][0] * px_per_m[1][1] - px_per_m[0][1] * px_per_m[1][0];
  require(std::abs(det) > 1.0, "px_per_m", "must be invertible (|det| > 1 px^2/m^2)", det);
  require(residual_rms_px >= 0.0 && std::isfinite(residual_rms_px), "residual_rms_px",
          "must be finite and >= 0", residual_rms_px);
}

AffineMap StageCalibration::map() const {
  AffineMap m;
  m.A << px_per_m[0][0], px_per_m[0][1], px_per_m[1][0], px_per_m[1][1];
  m.b << offset_px[0], offset_px[1];
  return m;
}

StageCalibration StageCalibration::of(const std::string& objective, const AffineFit& fit) {
  StageCalibration c;
  c.objective = objective;
  c.px_per_m = {{fit.map.A(0, 0), fit.map.A(0, 1)}, {fit.map.A(1, 0), fit.map.A(1, 1)}};
  c.offset_px = {fit.map.b.x(), fit.map.b.y()};
  c.residual_rms_px = fit.residual_rms_px;
  return c;
}

std::vector<Eigen::Vector2d> calibration_grid(const Eigen::Vector2d& centre_m, int n, double pitch_m) {
  require(n >= 2 && n <= 101, "grid points per side", "must be within [2, 101]", n);
  require(pitch_m > 0.0 && std::isfinite(pitch_m), "grid pitch_m", "must be finite and > 0", pitch_m);
  std::vector<Eigen::Vector2d> points;
  const double h = 0.5 * (n - 1);
  for (int i = 0; i < n; ++i) {
    for (int jj = 0; jj < n; ++jj) {
      const int j = i % 2 == 0 ? jj : n - 1 - jj;
      points.emplace_back(centre_m.x() + (j - h) * pitch_m, centre_m.y() + (i - h) * pitch_m);
    }
  }
  return points;
}

}  // namespace mc::vision
