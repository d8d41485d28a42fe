// The stage controller with the tracking controller on its axes (stage.tracking_enabled):
// a teleoperation-like moving target at the 1 kHz slave rate, the tracking controllers updated at
// every 10 kHz loop tick on the axis positions (drive(i, measured)), as the platform runs them.
#include <cmath>

#include <gtest/gtest.h>

#include "microcobot/motion/position_sensor.h"
#include "microcobot/platform/stage_controller.h"
#include "support/counting_allocator.h"

namespace mc::platform {
namespace {

TEST(StageTracking, FollowsAMovingTargetWithoutAllocating) {
  const stickslip::ActuatorModel model{stickslip::StickSlipParams{}};
  const motion::StepMap map(model);
  motion::TrackingParams tp;  // 10 kHz
  StageController ctrl(motion::PositionControlParams{}, model.params(), map, 10, 1e-5, &tp);
  ASSERT_NE(ctrl.tracker(0), nullptr);
  EXPECT_EQ(ctrl.axis(0), nullptr);
  std::array<stickslip::ActuatorState, 3> s{model.initial_state(), model.initial_state(),
                                            model.initial_state()};
  motion::PositionSensor sensor;
  double sq = 0.0, target = 0.0;
  int n = 0;
  std::size_t allocations = 0;
  {
    test::AllocationGuard guard;
    for (int tick = 0; tick < 3000; ++tick) {  // 0.3 s: 20 um at 100 um/s on X, then hold
      const double v = tick < 2000 ? 100e-6 : 0.0;
      target += v * 1e-4;
      if (tick % 10 == 0) {  // the 1 kHz slave tick
        ctrl.update(Eigen::Vector3d(target, 0.0, 0.0), Eigen::Vector3d(v, 0.0, 0.0),
                    {sensor.measure(model.slider_position(s[0])), model.slider_position(s[1]),
                     model.slider_position(s[2])});
      }
      for (int i = 0; i < 3; ++i) {
        const auto& st0 = s[static_cast<std::size_t>(i)];
        const devices::DriveBlock b =
            ctrl.drive(i, i == 0 ? sensor.measure(model.slider_position(st0)) : model.slider_position(st0));
        auto& st = s[static_cast<std::size_t>(i)];
        model.set_operating_point(
            st, b.amplitude_V, b.frequency_Hz > 0.0 ? b.frequency_Hz : 1000.0,
            b.direction < 0 ? stickslip::Direction::kBackward : stickslip::Direction::kForward);
        for (int k = 0; k < b.count; ++k) model.step(st, b.segments[k]);
      }
      const double e = model.slider_position(s[0]) - target;
      if (tick > 100 && tick < 2000) {
        sq += e * e;
        ++n;
      }
    }
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_LT(std::sqrt(sq / n), 300e-9);  // the hybrid controller lags by microns here
  EXPECT_NEAR(model.slider_position(s[0]), target, 5e-9);
  EXPECT_NEAR(model.slider_position(s[1]), 0.0, 5e-9);
  ctrl.emergency_stop();
  EXPECT_EQ(ctrl.last_voltage_V(0), 0.0);
}

}  // namespace
}  // namespace mc::platform
