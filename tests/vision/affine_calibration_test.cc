// The pixel <-> stage affine fit: a known map with a rotation, separate
// scales and a shear recovered from noisy tracked points; its figures; bad point sets refused.

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/vision/affine_calibration.h"

namespace mc::vision {
namespace {

constexpr double kDeg = M_PI / 180.0;

// 0.5 um/px along x, 0.52 along y, the stage's x axis at 3 deg, y 0.4 deg off perpendicular,
// image rows going down.
AffineMap known_map() {
  const double a = 3.0 * kDeg, b = a + 0.4 * kDeg;
  Eigen::Matrix2d g;
  g << std::cos(a) / 0.5e-6, -std::sin(b) / 0.52e-6, std::sin(a) / 0.5e-6, std::cos(b) / 0.52e-6;
  AffineMap m;
  m.A = Eigen::Vector2d(1.0, -1.0).asDiagonal() * g;
  m.b = Eigen::Vector2d(640.0, 512.0) - m.A * Eigen::Vector2d(-2e-4, 1e-3);
  return m;
}

TEST(AffineCalibration, RecoversScalesRotationAndShearFromNoisyPoints) {
  const AffineMap truth = known_map();
  const auto stage = calibration_grid({-2e-4, 1e-3}, 5, 60e-6);
  ASSERT_EQ(stage.size(), 25u);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 0.02);  // tracking noise [px]
  std::vector<Eigen::Vector2d> pixel;
  for (const auto& s : stage) pixel.push_back(truth.pixel_of(s) + Eigen::Vector2d(noise(rng), noise(rng)));
  const AffineFit fit = fit_affine(stage, pixel);
  EXPECT_LT(fit.residual_rms_px, 0.04);
  EXPECT_GT(fit.residual_rms_px, 0.01) << "the residual is the noise, not zero";
  const AffineFigures f = affine_figures(fit.map);
  EXPECT_NEAR(f.um_per_px_x, 0.5, 0.5 * 2e-3) << "within 0.2 %";
  EXPECT_NEAR(f.um_per_px_y, 0.52, 0.52 * 2e-3);
  EXPECT_NEAR(f.rotation_rad, 3.0 * kDeg, 0.02 * kDeg);
  EXPECT_NEAR(f.shear_rad, 0.4 * kDeg, 0.02 * kDeg);
  EXPECT_FALSE(f.mirrored);
  // Round trip through the map and its inverse.
  const Eigen::Vector2d s(-1.9e-4, 1.02e-3);
  EXPECT_LT((fit.map.stage_of(fit.map.pixel_of(s)) - s).norm(), 1e-12);
  EXPECT_LT((fit.map.stage_step(fit.map.pixel_step({1e-6, 0})) - Eigen::Vector2d(1e-6, 0)).norm(), 1e-15);
}

TEST(AffineCalibration, TheGridIsSerpentineAroundItsCentre) {
  const auto g = calibration_grid({1.0, 2.0}, 3, 0.5);
  ASSERT_EQ(g.size(), 9u);
  EXPECT_EQ(g[0], Eigen::Vector2d(0.5, 1.5));
  EXPECT_EQ(g[2], Eigen::Vector2d(1.5, 1.5));
  EXPECT_EQ(g[3], Eigen::Vector2d(1.5, 2.0)) << "the second row comes back";
  for (std::size_t k = 1; k < g.size(); ++k) EXPECT_NEAR((g[k] - g[k - 1]).norm(), 0.5, 1e-12);
  EXPECT_THROW(calibration_grid({0, 0}, 1, 1.0), InvalidParams);
  EXPECT_THROW(calibration_grid({0, 0}, 3, std::nan("")), InvalidParams);
}

TEST(AffineCalibration, RefusesPointSetsThatCannotDetermineTheMap) {
  const std::vector<Eigen::Vector2d> line = {{0, 0}, {1e-5, 1e-5}, {2e-5, 2e-5}, {3e-5, 3e-5}};
  const std::vector<Eigen::Vector2d> px = {{0, 0}, {10, 10}, {20, 20}, {30, 30}};
  EXPECT_THROW(fit_affine(line, px), InvalidInput);
  EXPECT_THROW(fit_affine(std::span(line).first(2), std::span(px).first(2)), InvalidInput);
  EXPECT_THROW(fit_affine(line, std::span(px).first(3)), InvalidInput);
  std::vector<Eigen::Vector2d> bad = {{0, 0}, {1e-5, 0}, {0, 1e-5}};
  std::vector<Eigen::Vector2d> bad_px = {{0, 0}, {10, 0}, {0, std::nan("")}};
  try {
    fit_affine(bad, bad_px);
    FAIL() << "a NaN point was accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("point 2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mc::vision
