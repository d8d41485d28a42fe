// Exact coverage of a turned rectangle (imaging/polygon_coverage): the cells' sum is its area at any
// angle, an unturned one matches the product of its overlaps, and a half-covered cell is half.

#include <cmath>

#include <gtest/gtest.h>

#include "microcobot/imaging/polygon_coverage.h"

namespace mc::imaging {
namespace {

TEST(PolygonCoverage, TheCellsSumToTheAreaAtAnyAngle) {
  for (const double deg : {0.0, 0.3, 7.0, 30.0, 45.0, 89.0, 123.0}) {
    const double t = deg * M_PI / 180.0;
    const RotatedRect r{10.3, 9.7, 4.2, 2.6, std::cos(t), std::sin(t)};
    double sum = 0.0;
    for (int y = 0; y < 20; ++y)
      for (int x = 0; x < 20; ++x) sum += cell_coverage(r, x, y);
    EXPECT_NEAR(sum, 4.0 * 4.2 * 2.6, 1e-9) << deg << " deg";
    EXPECT_NEAR(r.half_width(), std::abs(std::cos(t)) * 4.2 + std::abs(std::sin(t)) * 2.6, 1e-12);
  }
}

TEST(PolygonCoverage, EdgesCoverTheirShareOfACell) {
  const RotatedRect r{0.0, 0.0, 3.0, 3.0, 1.0, 0.0};
  EXPECT_DOUBLE_EQ(cell_coverage(r, 0.0, 0.0), 1.0);
  EXPECT_NEAR(cell_coverage(r, 2.5, 0.0), 0.5, 1e-12);   // the edge at x = 3 through the cell's middle
  EXPECT_NEAR(cell_coverage(r, 2.5, 2.5), 0.25, 1e-12);  // the corner
  EXPECT_DOUBLE_EQ(cell_coverage(r, 4.0, 0.0), 0.0);
  // Turned by 45 degrees about the cell's corner: a diamond (tips at distance 1) covers the
  // triangle (0, 0), (1, 0), (0, 1) of the cell.
  const double c = std::sqrt(0.5);
  const RotatedRect d{0.0, 0.0, c, c, c, c};
  EXPECT_NEAR(cell_coverage(d, 0.0, 0.0), 0.5, 1e-12);
  EXPECT_NEAR(cell_coverage(d, 0.0, -1.0), 0.5, 1e-12);
}

}  // namespace
}  // namespace mc::imaging
