// The XYZ stage of thesis §2.3: three axes from one controller object, end stops, e-stop.
#include <cmath>

#include <gtest/gtest.h>

#include "control_fixture.h"
#include "microcobot/core/error.h"
#include "microcobot/motion/xyz_stage.h"
#include "support/counting_allocator.h"

namespace mc::motion {
namespace {

TEST(XyzStage, ThreeAxesReachTheirTargetsTogether) {
  XyzStage stage(test::model(), test::step_map());
  stage.set_target(Axis::kX, 20e-6);
  stage.set_target(Axis::kY, -3e-6);
  stage.set_target(Axis::kZ, 50e-9);
  {
    mc::test::AllocationGuard guard;
    for (int k = 0; k < 100; ++k) stage.tick();
    EXPECT_EQ(guard.allocations(), 0u);
  }
  while (!stage.all_in_position() && stage.time_s() < 1.0) stage.tick();
  for (int k = 0; k < 100; ++k) stage.tick();  // 10 ms of hold
  ASSERT_TRUE(stage.all_in_position());
  EXPECT_NEAR(stage.status(Axis::kX).position_m, 20e-6, 5e-9);
  EXPECT_NEAR(stage.status(Axis::kY).position_m, -3e-6, 5e-9);
  EXPECT_NEAR(stage.status(Axis::kZ).position_m, 50e-9, 5e-9);
  EXPECT_FALSE(stage.fault());
}

TEST(XyzStage, EmergencyStopBringsEveryAxisTo0VInOneTick) {
  XyzStage stage(test::model(), test::step_map());
  for (auto a : {Axis::kX, Axis::kY, Axis::kZ}) stage.set_target(a, 30e-6);
  for (int k = 0; k < 37; ++k) stage.tick();
  double before = 0.0;
  for (auto a : {Axis::kX, Axis::kY, Axis::kZ}) before += stage.status(a).voltage_V;
  ASSERT_GT(before, 0.0);  // something was being driven
  stage.emergency_stop();
  stage.tick();
  for (auto a : {Axis::kX, Axis::kY, Axis::kZ}) {
    EXPECT_EQ(stage.status(a).voltage_V, 0.0);
    EXPECT_EQ(stage.status(a).mode, AxisMode::kEmergencyStop);
  }
  // Stays stopped until a new target arrives.
  for (int k = 0; k < 20; ++k) stage.tick();
  EXPECT_EQ(stage.status(Axis::kX).voltage_V, 0.0);
  stage.set_target(Axis::kX, 30e-6);
  for (int k = 0; k < 20; ++k) stage.tick();
  EXPECT_NE(stage.status(Axis::kX).mode, AxisMode::kEmergencyStop);
}

TEST(XyzStage, EndStopOnOneAxisIsReportedWhileTheOthersWork) {
  XyzStage stage(test::model(), test::step_map());
  const double half = 0.5 * test::model().params().slider.stroke_m;
  stage.place(Axis::kZ, -half + 20e-6);
  stage.set_target(Axis::kZ, -half - 1e-3);  // beyond the backward stop
  stage.set_target(Axis::kX, 5e-6);
  while (stage.time_s() < 0.3 &&
         !(stage.status(Axis::kZ).end_stop && stage.status(Axis::kX).mode == AxisMode::kHold)) {
    stage.tick();
  }
  EXPECT_TRUE(stage.status(Axis::kZ).end_stop);
  EXPECT_EQ(stage.status(Axis::kZ).voltage_V, 0.0);
  // It reached the stop (the last abrupt edge may pull it off by a fraction of a step).
  EXPECT_NEAR(stage.status(Axis::kZ).position_m, -half, 0.5e-6);
  EXPECT_NEAR(stage.status(Axis::kX).position_m, 5e-6, 5e-9);
  EXPECT_THROW(stage.place(Axis::kY, 1.0), InvalidParams);
  EXPECT_THROW(parse_axis("w"), UsageError);
}

}  // namespace
}  // namespace mc::motion
