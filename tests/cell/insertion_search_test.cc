// The insertion's search: the points it tries along the fingers' y, its range, the pin's seen
// offset as its centre, and the retreat before each shift.
#include "microcobot/cell/insertion_search.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

namespace mc::cell {
namespace {

TEST(InsertionSearch, TriesZeroThenAlternatesOutwardAlongTheFingersUntilItsRange) {
  InsertionSearch s;
  s.restart(0.0);  // fingers along x: their y is the world's y
  const Eigen::Vector2d bore(1e-3, 2e-3);
  EXPECT_TRUE(s.point(bore).isApprox(bore));
  const double step = 15e-6, range = 25e-6;
  const double expected[] = {15e-6, -15e-6};
  for (double y : expected) {
    ASSERT_TRUE(s.next_point(step, range));
    EXPECT_NEAR(s.point(bore).y() - bore.y(), y, 1e-15);
    EXPECT_NEAR(s.point(bore).x(), bore.x(), 1e-15);
  }
  EXPECT_FALSE(s.next_point(step, range));  // +30 um lies beyond 25 um
  EXPECT_EQ(s.tries(), 3);
  s.restart(0.0);
  EXPECT_EQ(s.tries(), 0);
  EXPECT_TRUE(s.point(bore).isApprox(bore));
}

TEST(InsertionSearch, SearchesAlongTheFingersAsTheyWereAndAroundTheHeldPin) {
  InsertionSearch s;
  s.restart(0.5 * std::numbers::pi);  // fingers turned 90 deg: their y is the world's -x
  EXPECT_NEAR(s.along_fingers().x(), -1.0, 1e-15);
  s.centre_on_held(4e-6);  // the pin 4 um along the fingers' y: aim 4 um the other way
  EXPECT_DOUBLE_EQ(s.held_offset_m(), 4e-6);
  const Eigen::Vector2d bore(0, 0);
  EXPECT_NEAR(s.point(bore).x(), 4e-6, 1e-15);
  ASSERT_TRUE(s.next_point(10e-6, 25e-6));  // the first point beside the centre, not the bore
  EXPECT_NEAR(s.point(bore).x(), 4e-6 - 10e-6, 1e-15);
  s.shift_aim({1e-6, -2e-6});  // the servo's correction adds to every point
  EXPECT_NEAR(s.point(bore).y(), -2e-6, 1e-15);
}

TEST(InsertionSearch, RetreatsFromWhereTheDescentStoppedOrFromTheTip) {
  InsertionSearch s;
  s.restart(0.0);
  EXPECT_EQ(s.phase(), InsertionSearch::Phase::kDescend);
  s.retreat_from({1e-6, 2e-6}, 300e-6);
  EXPECT_EQ(s.phase(), InsertionSearch::Phase::kRetreat);
  EXPECT_TRUE(s.retreat_known());
  EXPECT_DOUBLE_EQ(s.retreat_z_m(), 300e-6);
  s.retreat_from_tip();
  EXPECT_FALSE(s.retreat_known());
  EXPECT_TRUE(std::isnan(s.contact_z_m()));
  s.record_contact(250e-6);
  EXPECT_DOUBLE_EQ(s.contact_z_m(), 250e-6);
}

}  // namespace
}  // namespace mc::cell
