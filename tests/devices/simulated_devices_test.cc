#include <gtest/gtest.h>

#include <array>

#include "microcobot/devices/simulated_gripper.h"
#include "microcobot/devices/simulated_haptic_master.h"
#include "microcobot/devices/simulated_slave_axis.h"
#include "microcobot/devices/simulated_tweezers_master.h"
#include "support/counting_allocator.h"

namespace mc::devices {
namespace {

constexpr double kDt = 1e-4;

TEST(SimulatedSlaveAxis, PlaysItsDriveClampedToTheAmplifierRangeOnlyWhileActive) {
  const stickslip::ActuatorModel model{stickslip::StickSlipParams{}};
  SimulatedSlaveAxis axis("x", model, motion::PositionSensorParams{}, 1e-3);
  axis.configure();
  EXPECT_NEAR(axis.true_position_m(), 1e-3, 1e-12);
  std::array<stickslip::DriveSegment, 10> volts;
  volts.fill(stickslip::DriveSegment::to(150.0));  // above the 100 V amplifier
  axis.command_drive(DriveBlock{volts.data(), 10, 0, 0, 0});
  axis.update(kDt);
  EXPECT_DOUBLE_EQ(axis.voltage_V(), 0.0);  // not active: commands ignored, 0 V
  axis.activate();
  for (int i = 0; i < 20; ++i) {
    axis.command_drive(DriveBlock{volts.data(), 10, 0, 0, 0});
    axis.update(kDt);
  }
  EXPECT_DOUBLE_EQ(axis.voltage_V(), model.params().drive.max_V);
  // 100 V extends the PE and the carriage moves forward with it (slewed at 1 V/us).
  EXPECT_GT(axis.true_position_m(), 1e-3 + 50e-9);
  axis.fault();
  for (int i = 0; i < 20; ++i) axis.update(kDt);
  EXPECT_DOUBLE_EQ(axis.voltage_V(), 0.0);                        // safe state: 0 V through the slew limit
  EXPECT_NEAR(axis.position_m(), axis.true_position_m(), 10e-9);  // the sensor reads ~1 nm RMS
}

TEST(SimulatedHapticMaster, AForceDisplacesTheHandleByTheFingerCompliance) {
  haptics::DualStagePlantParams plant;
  SimulatedHapticMaster m("dual_stage", plant, haptics::RenderPipelineParams{}, haptics::PantographParams{},
                          kDt);
  m.configure();
  m.activate();
  m.set_operator({{0.01, 0.0}, true, false, 0.0});
  const auto readings = m.reading_count();
  for (int i = 0; i < 20000; ++i) {  // 2 s: the finger mode (228 N/m on ~0.25 kg) settles
    m.command_force_N({0.2, 0.2});
    m.update(kDt);
  }
  EXPECT_EQ(m.reading_count(), readings + 20000);
  const Vec2 h = m.handle_position_m();
  EXPECT_NEAR(h.x - 0.01, 0.2 / plant.k_f_N_per_m, 1e-9);
  // y goes through the crossover (eq. 3.5-3.8): the low band is the Pantograph's, statically F.
  EXPECT_NEAR(h.y / (0.2 / plant.k_f_N_per_m), 1.0, 0.05);
  m.freeze_readings(true);
  m.update(kDt);
  EXPECT_EQ(m.reading_count(), readings + 20000);
  m.deactivate();  // safe state: no force, the handle returns to the hand
  for (int i = 0; i < 20000; ++i) m.update(kDt);
  EXPECT_NEAR(m.handle_position_m().y, 0.0, 1e-5);
}

TEST(SimulatedTweezersMaster, OperatorClosesTheTipsAndFeelsTheGripForce) {
  const tweezers::TeleTweezParams p;
  SimulatedTweezersMaster tw("teletweez", p, kDt);
  tw.configure();
  tw.activate();
  EXPECT_NEAR(tw.opening_m(), p.static_opening_tip_m, 1e-12);
  tw.set_operator_closing(5e-3);
  for (int i = 0; i < 20000; ++i) tw.update(kDt);
  const double free_opening = tw.opening_m();
  // Static balance on each lever: (k_clamp + k_f) x = k_f x_target; the tips close twice x.
  const double x =
      p.finger_stiffness_N_per_m * 5e-3 / (p.finger_stiffness_N_per_m + p.clamping_stiffness_N_per_m);
  EXPECT_NEAR(free_opening, p.static_opening_tip_m - 2 * x, 20e-6);
  for (int i = 0; i < 20000; ++i) {
    tw.command_grip_force_N(0.5);
    tw.update(kDt);
  }
  EXPECT_GT(tw.opening_m(), free_opening + 1e-3);  // the rendered grip pushes the fingers back
  EXPECT_LT(tw.motor_torque_N_m(), 0.0);
  tw.fault();
  tw.update(kDt);
  EXPECT_DOUBLE_EQ(tw.motor_torque_N_m(), 0.0);
}

TEST(SimulatedGripper, ClosesOnThePartUnderTheStageAndStepsWithoutAllocating) {
  const stickslip::ActuatorModel model{stickslip::StickSlipParams{}};
  const microworld::PickPlaceWorld world{microworld::PickPlaceParams{}};
  SimulatedSlaveAxis x("x", model, {}, 0.0), y("y", model, {}, 0.0), z("z", model, {}, 0.0);
  SimulatedGripper g("gripper", world, {&x, &y, &z}, Vec3{0.0, 0.0, 100e-6});  // tips at the part
  for (Device* d : std::array<Device*, 4>{&x, &y, &z, &g}) {
    d->configure();
    d->activate();
  }
  std::size_t allocations = 0;
  {
    test::AllocationGuard guard;
    for (int i = 0; i < 1000; ++i) {
      g.command_opening_m(260e-6);
      g.update(kDt);
    }
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_DOUBLE_EQ(g.opening_m(), 300e-6);  // blocked by the 300 um part
  EXPECT_NEAR(g.grip_force_N(), 0.5 * 50.0 * 40e-6, 1e-9);
  g.fault();  // safe state keeps the grip: the part is not dropped
  g.update(kDt);
  EXPECT_GT(g.grip_force_N(), 0.0);
}

TEST(SimulatedGripper, ItsAlignDrivesLevelMisalignedTipsAndItsTipsFeelTheSubstrate) {
  const stickslip::ActuatorModel model{stickslip::StickSlipParams{}};
  microworld::PickPlaceParams p;
  p.gripper.tip_misalignment_m = 20e-6;
  const microworld::PickPlaceWorld world{p};
  SimulatedSlaveAxis x("x", model, {}, 0.0), y("y", model, {}, 0.0), z("z", model, {}, 0.0);
  // Away from the part, the reference 5 um above the substrate: finger 0's tip, 10 um lower, presses.
  SimulatedGripper g("gripper", world, {&x, &y, &z}, Vec3{1e-3, 1e-3, 5e-6});
  EXPECT_TRUE(g.has_align_drives());
  EXPECT_DOUBLE_EQ(g.align_limit_V(), 150.0);
  g.command_align_V({0.0, -50.0});  // not configured: ignored
  for (Device* d : std::array<Device*, 4>{&x, &y, &z, &g}) {
    d->configure();
    d->activate();
  }
  EXPECT_EQ(g.align_V(), (std::array<double, 2>{0.0, 0.0}));
  g.update(kDt);
  EXPECT_NEAR(g.tip_contact_N()[0], 50.0 * 5e-6, 1e-12);
  EXPECT_DOUBLE_EQ(g.tip_contact_N()[1], 0.0);
  EXPECT_NEAR(g.tip_misalignment_m(), 20e-6, 1e-15);
  g.command_align_V({0.0, -500.0});  // clamped to the drive's range
  EXPECT_EQ(g.align_V(), (std::array<double, 2>{0.0, -150.0}));
  g.command_align_V({0.0, std::nan("")});  // refused whole
  EXPECT_EQ(g.align_V(), (std::array<double, 2>{0.0, -150.0}));
  g.command_align_V({0.0, -30.0});
  std::size_t allocations = 0;
  {
    test::AllocationGuard guard;
    for (int i = 0; i < 20000; ++i) g.update(kDt);
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  // Finger 1's tip brought down by about 1 um/V less the hysteresis' share, past finger 0's and onto
  // the substrate (5 um below the reference).
  EXPECT_LT(g.tip_misalignment_m(), 0.0);
  EXPECT_GT(g.tip_misalignment_m(), -10e-6);
  EXPECT_GT(g.tip_contact_N()[1], 0.0);
  g.fault();  // the safe state holds the drives where they are
  g.command_align_V({0.0, 0.0});
  EXPECT_EQ(g.align_V(), (std::array<double, 2>{0.0, -30.0}));
}

}  // namespace
}  // namespace mc::devices
