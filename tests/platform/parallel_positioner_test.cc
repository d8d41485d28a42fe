// The parallel positioner as a device of the platform (`positioner: parallel`, the thesis's
// assembly): chosen by the configuration, its pose in the telemetry, updated on the loop without
// allocating, moved only under the deadman of the input that drives the coupling, every leg at
// 0 V on an e-stop or a fault of its model, which puts every device in its safe state.

#include <gtest/gtest.h>

#include <fstream>
#include <numbers>

#include "microcobot/core/error.h"
#include "microcobot/motion/pose.h"
#include "microcobot/platform/platform.h"
#include "support/counting_allocator.h"
#include "support/test_support.h"

namespace mc::platform {
namespace {

using motion::PlatformTransform;
using motion::SmarPodPose;
constexpr double kDeg = std::numbers::pi / 180.0;

PlatformConfig parallel() {
  PlatformConfig c;
  c.positioner = "parallel";
  return c;
}

/// The console holding control: active, fresh, and its deadman as given (no stage motion asked).
void console(Platform& p, bool deadman, bool fresh = true) {
  teleop::ConsoleInput in;
  in.active = true;
  in.fresh = fresh;
  in.deadman = deadman;
  in.goal_m = {p.config().stage.home_x_m, p.config().stage.home_y_m, p.config().stage.home_z_m};
  p.set_console_input(in);
}

/// A checked move from the pose the legs hold to `goal`.
motion::PoseTrajectory move_to(const Platform& p, const SmarPodPose& goal) {
  motion::PoseTrajectory t(p.positioner()->reference_pose(), motion::to_transform(goal),
                           p.config().parallel_positioner.move);
  const motion::MoveCheck c = motion::check_move(p.positioner()->kinematics(), t);
  EXPECT_TRUE(c.ok) << c.reason;
  return t;
}

const devices::SimulatedParallelPositioner& sim(const Platform& p) { return *p.simulation().positioner; }

double distance_m(const PlatformTransform& a, const PlatformTransform& b) { return (a.d - b.d).norm(); }

TEST(PositionerDevice, TheConfigurationChoosesTheCartesianStageOrTheThesisAssembly) {
  const Platform cartesian{PlatformConfig{}};
  EXPECT_FALSE(cartesian.has_positioner());
  EXPECT_FALSE(cartesian.telemetry_schema().find("positioner_x_m"));
  Platform p{parallel()};
  ASSERT_TRUE(p.has_positioner());
  EXPECT_EQ(p.positioner()->state(), devices::Lifecycle::kActive);
  for (const char* name :
       {"positioner_x_m", "positioner_y_m", "positioner_z_m", "positioner_rx_rad", "positioner_ry_rad",
        "positioner_rz_rad", "positioner_true_x_m", "positioner_true_rz_rad", "positioner_u_max_V"})
    EXPECT_TRUE(p.telemetry_schema().find(name)) << name;
  // The gripper stays on the Cartesian robot: its channels are there as before.
  EXPECT_EQ(p.telemetry_schema().first(cartesian.telemetry_channel_count()), cartesian.telemetry_schema());
  // Bad values are one line naming the key and what was given.
  test::TempDir dir;
  std::ofstream(dir / "platform.yaml") << "positioner: hexapod\n";
  try {
    load_platform_config(dir / "platform.yaml");
    FAIL() << "accepted positioner: hexapod";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("positioner"), std::string::npos) << what;
    EXPECT_NE(what.find("'hexapod'"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(PositionerDevice, ItsPoseReachesTheTelemetryMeasuredAndTrue) {
  Platform p{parallel()};
  p.run(0.2);  // the legs power up at home
  console(p, true);
  ASSERT_TRUE(p.start_pose_move(move_to(p, {30e-6, -20e-6, 10e-6, 0.05 * kDeg, 0.0, -0.1 * kDeg})));
  p.run(2.0);
  ASSERT_FALSE(p.positioner()->moving());
  const TelemetrySchema& s = p.telemetry_schema();
  const Recorder& rec = p.recording();
  const std::size_t last = rec.size() - 1;
  // On target within a micron and a millidegree (the hexapod twin's tolerance), measured and true.
  EXPECT_NEAR(rec.at(last, s.index("positioner_x_m")), 30e-6, 1e-6);
  EXPECT_NEAR(rec.at(last, s.index("positioner_y_m")), -20e-6, 1e-6);
  EXPECT_NEAR(rec.at(last, s.index("positioner_z_m")), 10e-6, 1e-6);
  EXPECT_NEAR(rec.at(last, s.index("positioner_rz_rad")), -0.1 * kDeg, 1e-3 * kDeg);
  EXPECT_NEAR(rec.at(last, s.index("positioner_true_x_m")), 30e-6, 1e-6);
  EXPECT_NEAR(rec.at(last, s.index("positioner_true_rx_rad")), 0.05 * kDeg, 1e-3 * kDeg);
  EXPECT_EQ(rec.at(last, s.index("positioner_moving")), 0.0);
}

TEST(PositionerDevice, APoseMoveRunsOnlyWithTheDeadmanAndHoldsWhenItDropsOrGoesStale) {
  Platform p{parallel()};
  p.loop().run_for(2000);  // 0.2 s: the legs power up
  const PlatformTransform home = sim(p).true_pose();
  // Without the deadman (or without any input driving), nothing starts.
  EXPECT_FALSE(p.start_pose_move(move_to(p, {0.2e-3, 0, 0, 0, 0, 0})));
  console(p, false);
  EXPECT_FALSE(p.start_pose_move(move_to(p, {0.2e-3, 0, 0, 0, 0, 0})));
  p.loop().run_for(3000);
  EXPECT_LT(distance_m(sim(p).true_pose(), home), 50e-9);
  // With it, the move runs...
  console(p, true);
  ASSERT_TRUE(p.start_pose_move(move_to(p, {0.2e-3, 0, 0, 0, 0, 0})));
  EXPECT_FALSE(p.start_pose_move(move_to(p, {0.1e-3, 0, 0, 0, 0, 0})));  // one at a time
  p.loop().run_for(5000);
  ASSERT_TRUE(p.positioner()->moving());
  EXPECT_GT(distance_m(sim(p).true_pose(), home), 10e-6);
  // ... and holds where it is as soon as the deadman drops.
  console(p, false);
  p.loop().run_for(1);
  EXPECT_FALSE(p.positioner()->moving());
  const PlatformTransform held = p.positioner()->reference_pose();
  p.loop().run_for(200);
  const PlatformTransform at_stop = sim(p).true_pose();
  p.loop().run_for(5000);
  EXPECT_LT(distance_m(sim(p).true_pose(), at_stop), 0.3e-6);
  EXPECT_EQ(p.positioner()->reference_pose().d, held.d);
  // A stale input (the deadman held, its commands late) holds it too.
  console(p, true);
  ASSERT_TRUE(p.start_pose_move(move_to(p, {0.2e-3, 0, 0, 0, 0, 0})));
  p.loop().run_for(3000);
  ASSERT_TRUE(p.positioner()->moving());
  console(p, true, /*fresh=*/false);
  p.loop().run_for(1);
  EXPECT_FALSE(p.positioner()->moving());
  // A hand-over (Platform::hold) holds it as well.
  console(p, true);
  ASSERT_TRUE(p.start_pose_move(move_to(p, {0.2e-3, 0, 0, 0, 0, 0})));
  p.loop().run_for(1000);
  p.hold();
  EXPECT_FALSE(p.positioner()->moving());
}

TEST(PositionerDevice, AnEstopHoldsEveryLegAtZeroVoltsUntilTheResetWhichHoldsWhereItStopped) {
  Platform p{parallel()};
  p.loop().run_for(2000);
  console(p, true);
  ASSERT_TRUE(p.start_pose_move(move_to(p, {0.2e-3, 0.1e-3, 0, 0, 0, 0.2 * kDeg})));
  p.loop().run_for(5000);
  ASSERT_TRUE(p.positioner()->moving());
  p.fault_all();
  p.fault_all();  // idempotent
  EXPECT_EQ(p.positioner()->state(), devices::Lifecycle::kFault);
  EXPECT_FALSE(p.positioner()->moving());
  p.loop().run_for(10);
  const PlatformTransform at_stop = sim(p).true_pose();
  p.loop().run_for(3000);
  for (int i = 0; i < motion::kParallelAxes; ++i) EXPECT_EQ(sim(p).stage().status(i).voltage_V, 0.0) << i;
  EXPECT_EQ(p.positioner()->max_leg_voltage_V(), 0.0);
  EXPECT_LT(distance_m(sim(p).true_pose(), at_stop), 0.3e-6);  // 0 V: nothing steps
  EXPECT_FALSE(p.start_pose_move(move_to(p, {0, 0, 0, 0, 0, 0})));
  // The reset: armed again, the legs hold where they are measured.
  p.recover();
  EXPECT_EQ(p.positioner()->state(), devices::Lifecycle::kActive);
  EXPECT_LT(distance_m(p.positioner()->reference_pose(), p.positioner()->measured_pose()), 1e-12);
  const PlatformTransform rest = sim(p).true_pose();
  p.loop().run_for(5000);
  EXPECT_LT(distance_m(sim(p).true_pose(), rest), 0.3e-6);
  ASSERT_TRUE(p.start_pose_move(move_to(p, {0, 0, 0, 0, 0, 0})));
}

TEST(PositionerDevice, AFaultOfItsModelPutsEveryDeviceInItsSafeState) {
  Platform p{parallel()};
  p.loop().run_for(2000);
  ASSERT_FALSE(p.faulted());
  // The legs stepped open loop to their end stops one after the other, the last ones against the
  // first: the sensors come to read leg coordinates where no pose of the positioner is (a passive
  // joint beyond its limit, legs that do not close), and the forward kinematics fails.
  using motion::LegPositioner;
  const struct {
    int leg;
    LegPositioner positioner;
    int direction;
  } runs[] = {{0, LegPositioner::kRadial, 1},  {0, LegPositioner::kTangential, 1},
              {1, LegPositioner::kRadial, -1}, {1, LegPositioner::kTangential, -1},
              {2, LegPositioner::kRadial, 1},  {2, LegPositioner::kTangential, 1}};
  for (const auto& run : runs) {
    if (p.faulted()) break;
    p.simulation().positioner->step_leg(run.leg, run.positioner, run.direction * 8000, 2000.0);
    for (int k = 0; k < 100 && !p.faulted() &&
                    sim(p).stage().status(2 * run.leg + static_cast<int>(run.positioner)).stepping;
         ++k)
      p.loop().run_for(1000);
  }
  ASSERT_TRUE(p.faulted());
  EXPECT_TRUE(sim(p).stage().fault());
  EXPECT_EQ(p.positioner()->state(), devices::Lifecycle::kFault);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(p.axis(i).state(), devices::Lifecycle::kFault) << i;
  EXPECT_EQ(p.gripper().state(), devices::Lifecycle::kFault);
  p.loop().run_for(1000);
  EXPECT_EQ(p.positioner()->max_leg_voltage_V(), 0.0);
  for (int i = 0; i < 3; ++i)
    EXPECT_DOUBLE_EQ(p.simulation().axes[static_cast<std::size_t>(i)]->voltage_V(), 0.0);
  // The reset is refused: the model's fault stays latched.
  EXPECT_THROW(p.recover(), Error);
  EXPECT_TRUE(p.faulted());
}

TEST(PositionerDevice, TheLoopPathNeitherAllocatesWhileThePositionerMovesStopsAndFaults) {
  Platform p{parallel()};
  p.loop().run_for(2000);  // warm-up: first touches
  console(p, true);
  const motion::PoseTrajectory out = move_to(p, {0.1e-3, 0, 0, 0.1 * kDeg, 0, 0});
  std::size_t allocations = 0;
  {
    test::AllocationGuard guard;
    const bool started = p.start_pose_move(out);
    p.loop().run_for(5000);
    const bool moved = p.positioner()->moving();
    console(p, false);  // the deadman drops: held
    p.loop().run_for(2000);
    p.fault_all();
    p.loop().run_for(2000);
    allocations = guard.allocations();
    EXPECT_TRUE(started);
    EXPECT_TRUE(moved);
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_EQ(p.telemetry_dropped(), 0u);
}

}  // namespace
}  // namespace mc::platform
