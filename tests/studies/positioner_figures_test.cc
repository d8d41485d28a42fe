#include "microcobot/studies/positioner_figures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace mc::studies {
namespace {

const report::Series* series_named(const report::Figure& f, const std::string& name) {
  const auto it =
      std::find_if(f.series.begin(), f.series.end(), [&](const report::Series& s) { return s.name == name; });
  return it == f.series.end() ? nullptr : &*it;
}

double result_value(const report::Section& s, const std::string& prefix) {
  for (const report::Result& r : s.results)
    if (r.name.rfind(prefix, 0) == 0) return r.value;
  ADD_FAILURE() << "no result " << prefix;
  return 0.0;
}

TEST(PositionerFigures, TheSlicesShowTheReachableRegionInsideItsRefusedBorder) {
  report::Report r("positioner");
  positioner_figures(r);
  ASSERT_EQ(r.sections().size(), 1u);
  const report::Section& s = r.sections()[0];
  ASSERT_EQ(s.figures.size(), 2u);
  for (const report::Figure& f : s.figures) {
    const report::Series* ok = series_named(f, "reachable");
    ASSERT_NE(ok, nullptr) << f.title;
    // Home (0, 0) is reachable and the slice's edge is not all reachable: the border is drawn.
    EXPECT_GT(ok->x.size(), 1u);
    EXPECT_LT(ok->x.size(), 41u * 41u) << f.title;
    const bool home_in =
        std::any_of(ok->x.begin(), ok->x.end(), [&](double x) { return std::abs(x) < 1e-9; });
    EXPECT_TRUE(home_in) << f.title;
    std::size_t points = 0;
    for (const report::Series& ser : f.series) points += ser.x.size();
    EXPECT_EQ(points, 41u * 41u) << f.title;
  }
  // Displayed in mm and deg: the x-y slice spans +-8 mm, the rx-ry slice +-15 deg.
  const auto [lo, hi] = std::minmax_element(s.figures[0].series[0].x.begin(), s.figures[0].series[0].x.end());
  EXPECT_GE(*lo, -8.0 - 1e-9);
  EXPECT_LE(*hi, 8.0 + 1e-9);
  EXPECT_EQ(s.figures[0].x.unit, "mm");
  EXPECT_EQ(s.figures[1].x.unit, "deg");
  EXPECT_DOUBLE_EQ(result_value(s, "reachable points, x-y"),
                   static_cast<double>(series_named(s.figures[0], "reachable")->x.size()));
}

TEST(PositionerFigures, EachRotationTurnsBothWaysFromHomeAndLessOffCentre) {
  report::Report r("positioner");
  positioner_figures(r);
  const report::Section& s = r.sections()[0];
  for (const char* n : {"rx", "ry", "rz"}) {
    const std::string at_home = std::string(n) + " travel at home: ";
    const std::string off = std::string(n) + " travel at x = 4 mm: ";
    const double lo_home = result_value(s, at_home + "min"), hi_home = result_value(s, at_home + "max");
    const double lo_off = result_value(s, off + "min"), hi_off = result_value(s, off + "max");
    EXPECT_LT(lo_home, 0.0) << n;
    EXPECT_GT(hi_home, 0.0) << n;
    EXPECT_LE(hi_off - lo_off, hi_home - lo_home + 1e-9) << n;
  }
}

}  // namespace
}  // namespace mc::studies
