#pragma once
/// @file
/// Pixel <-> stage calibration: the full affine map from the stage's
/// commanded coordinates to the image, measured by moving the stage through a pattern and
/// tracking a feature that moves with it (Micro-Manager's pixel-size calibration does the same).
///
///     p = A s + b        p: pixel (column u, row v), s: stage (x, y) [m]
///
/// A holds everything between the stage's axes and the sensor's: the magnification (per axis:
/// the stage's scale errors), the camera's rotation on the microscope, the non-orthogonality of
/// the stage's axes (shear) and the image's rows going down while stage y goes up (a reflection).
/// Fitted by linear least squares over the pattern's points (6 unknowns, >= 3 points not on a
/// line); the residuals say how affine the real map is (lens distortion, tracking noise).

#include <Eigen/Dense>
#include <span>
#include <string>
#include <vector>

namespace mc::vision {

struct AffineMap {
  Eigen::Matrix2d A = Eigen::Matrix2d::Identity();  ///< [px/m]
  Eigen::Vector2d b = Eigen::Vector2d::Zero();      ///< [px]

  Eigen::Vector2d pixel_of(const Eigen::Vector2d& stage_m) const { return A * stage_m + b; }
  /// The stage point imaged at `pixel` (A invertible: a fitted map always is).
  Eigen::Vector2d stage_of(const Eigen::Vector2d& pixel) const { return A.lu().solve(pixel - b); }
  /// A stage displacement seen as an image displacement, and back.
  Eigen::Vector2d pixel_step(const Eigen::Vector2d& stage_step_m) const { return A * stage_step_m; }
  Eigen::Vector2d stage_step(const Eigen::Vector2d& pixel_step) const { return A.lu().solve(pixel_step); }
};

/// The map's figures in the words of a microscope user. With the image's rows flipped (y up),
/// A' = diag(1, -1) A; the stage's x axis appears along A'e_x, its y axis along A'e_y.
struct AffineFigures {
  double um_per_px_x = 0.0;   ///< stage x: micrometres per pixel of image motion
  double um_per_px_y = 0.0;   ///< stage y
  double rotation_rad = 0.0;  ///< the stage's x axis in the image (counter-clockwise, y up)
  double shear_rad = 0.0;     ///< angle between the stage's axes as seen, minus 90 degrees
  bool mirrored = false;      ///< the stage's (x, y) appear left-handed in the (y-up) image
};
AffineFigures affine_figures(const AffineMap& map);

struct AffineFit {
  AffineMap map;
  double residual_rms_px = 0.0;
  double residual_max_px = 0.0;
  std::vector<Eigen::Vector2d> residuals_px;  ///< measured - fitted, per point
};

/// Least-squares affine map through the pairs (stage[k], pixel[k]). Throws mc::InvalidInput when
/// the lengths differ, a value is not finite, or the stage points do not span the plane (fewer than
/// three, or all on a line).
AffineFit fit_affine(std::span<const Eigen::Vector2d> stage_m, std::span<const Eigen::Vector2d> pixel);

/// A calibration as the configuration stores it (`camera.calibrations`, one per objective;
/// written by `microcobot vision calibrate --save FILE`): pixel = A stage + b.
struct StageCalibration {
  std::string objective;                      ///< the turret's objective it was measured with
  std::vector<std::vector<double>> px_per_m;  ///< A, 2 x 2, rows (u, v) [px/m]
  std::vector<double> offset_px;              ///< b, (u, v) [px]
  double residual_rms_px = 0.0;               ///< the fit's residual when measured

  template <class V>
  void visit(V& v) {
    v("objective", objective);
    v("px_per_m", px_per_m);
    v("offset_px", offset_px);
    v("residual_rms_px", residual_rms_px);
  }
  /// Throws mc::InvalidParams naming the field: a name, a 2 x 2 finite invertible A, a finite b.
  void validate() const;
  AffineMap map() const;
  static StageCalibration of(const std::string& objective, const AffineFit& fit);
};

/// The stage points of an n x n grid of `pitch_m` centred on `centre_m`, in serpentine order (each
/// row reversed from the last: no long return moves). n >= 2.
std::vector<Eigen::Vector2d> calibration_grid(const Eigen::Vector2d& centre_m, int n, double pitch_m);

}  // namespace mc::vision
