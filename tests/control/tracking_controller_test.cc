// Trajectory tracking within one step (issue #15): the reference-phased sawtooth against today's
// hybrid controller and the thesis's PID on the same model, sensor noise and reference.
#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "control_fixture.h"
#include "microcobot/control/tracking_run.h"
#include "microcobot/core/error.h"
#include "support/counting_allocator.h"

namespace mc::control {
namespace {

using stickslip::Direction;

TrackingRecord trapezoid(TrackerKind kind, double distance_m, double velocity_m_s,
                         const TrackerSetup& su = {}) {
  const MotionLimits lim{velocity_m_s, 2e-3};
  const double start = -0.5 * distance_m, end = start + distance_m;
  auto l = std::make_shared<ReferenceLimiter>(lim, start);
  auto setup = su;
  setup.hybrid.scan_velocity_m_s = std::max(setup.hybrid.scan_velocity_m_s, 1.5 * velocity_m_s);
  setup.hybrid.scan_acceleration_m_s2 = std::max(setup.hybrid.scan_acceleration_m_s2, 3e-3);
  return run_tracker(
      test::model(), test::step_map(), kind, setup, start,
      [l, end](double, double dt) { return l->step(end, dt); },
      trapezoid_duration_s(std::abs(distance_m), lim) + 0.05);
}

// The goals are RMS <= 100 nm and max <= 250 nm: not reached on this model (each edge
// leaves a ~300-500 nm transient of the contact, docs/errata.md). These bounds are the measured
// figures (117-125 nm RMS, 400-650 nm max on the CLI's runs) with a margin; they fail if the
// controller regresses (159-161 nm before the damping of kp < 0).
TEST(TrackingController, TrapezoidAt200umPerSecondBothDirections) {
  for (double d : {100e-6, -100e-6}) {
    SCOPED_TRACE(d);
    const auto t = trapezoid(TrackerKind::kTracking, d, 200e-6).metrics;
    const auto h = trapezoid(TrackerKind::kHybrid, d, 200e-6).metrics;
    EXPECT_LE(t.rms_error_m, 150e-9);
    EXPECT_LE(t.max_error_m, 900e-9);
    EXPECT_LE(t.final_error_m, 5e-9);  // issue goal: final error unchanged
    EXPECT_LE(t.lag_s, 0.5e-3);
    EXPECT_LT(t.rms_error_m, 0.25 * h.rms_error_m);  // >= 4x better than today's controller
    EXPECT_GT(t.edges, 100);                         // it stepped (~0.5 um per edge)
  }
}

TEST(TrackingController, TrapezoidAt50And500umPerSecond) {
  for (double v : {50e-6, 500e-6}) {
    SCOPED_TRACE(v);
    const auto t = trapezoid(TrackerKind::kTracking, 100e-6, v).metrics;
    EXPECT_LE(t.rms_error_m, 300e-9);
    EXPECT_LE(t.final_error_m, 5e-9);
  }
}

TEST(TrackingController, SineOf20umAt1Hz) {
  const MotionLimits lim{200e-6, 2e-3};
  auto sine = std::make_shared<SineReference>(0.0, 20e-6, 1.0, lim);
  const auto r = run_tracker(
      test::model(), test::step_map(), TrackerKind::kTracking, TrackerSetup{}, 0.0,
      [sine](double t, double) { return sine->at(t); }, 1.0);
  EXPECT_LE(r.metrics.rms_error_m, 120e-9);  // measured 92-94 nm (issue goal: 100 nm)
  EXPECT_LE(r.metrics.max_error_m, 1e-6);
}

TEST(TrackingController, AnAxisThatFellBehindCatchesUp) {
  // 400 um at 2 mm/s: faster than the edges can step (1.5 mm/s is still followed, docs/errata.md),
  // so the axis falls behind; once the reference stops it must still arrive, at full stepping
  // speed. (With the wait disabled, tracking.edge_ready_V = 50, an axis this far behind takes its
  // edges straight after each unloading and ends this run 351 um short.)
  const MotionLimits lim{2e-3, 0.1};
  auto l = std::make_shared<ReferenceLimiter>(lim, -200e-6);
  const auto r = run_tracker(
      test::model(), test::step_map(), TrackerKind::kTracking, TrackerSetup{}, -200e-6,
      [l](double, double dt) { return l->step(200e-6, dt); }, trapezoid_duration_s(400e-6, lim) + 0.3);
  EXPECT_GT(r.metrics.max_error_m, 5e-6);  // it did fall behind
  EXPECT_LE(r.metrics.final_error_m, 5e-9);
}

TEST(TrackingController, WithinThePeStrokeItOnlyScans) {
  // A 400 nm move fits the PE's range: no edge (step-scan blending: no mode switch, no step).
  const auto t = trapezoid(TrackerKind::kTracking, 400e-9, 200e-6).metrics;
  EXPECT_EQ(t.edges, 0);
  EXPECT_LE(t.max_error_m, 30e-9);
  EXPECT_LE(t.final_error_m, 5e-9);
}

TEST(TrackingController, EdgesGoTheWayTheReferenceMoves) {
  TrackingController c(TrackingParams{}, test::model().params(), test::step_map());
  auto s = test::model().initial_state();
  c.reset(0.0, 0.0);
  PositionSensor sensor;
  double x_ref = 0.0;
  for (int k = 0; k < 2000; ++k) {  // 0.2 s backward at 100 um/s
    x_ref -= 100e-6 * 1e-4;
    c.set_reference({x_ref, -100e-6, 0.0});
    c.update(sensor.measure(test::model().slider_position(s)));
    if (c.in_edge()) {
      EXPECT_EQ(c.operating_point().direction, Direction::kBackward);
    }
    test::model().set_operating_point(s, c.operating_point().amplitude_V, c.operating_point().frequency_Hz,
                                      c.operating_point().direction);
    for (int i = 0; i < 10; ++i) test::model().step(s, c.next_drive(1e-5));
  }
  EXPECT_GT(c.edges(), 10);
  EXPECT_NEAR(test::model().slider_position(s), x_ref, 1.5e-6);
}

TEST(TrackingController, UpdateAndDriveNeverAllocate) {
  TrackingController c(TrackingParams{}, test::model().params(), test::step_map());
  auto s = test::model().initial_state();
  PositionSensor sensor;
  c.reset(0.0, 0.0);
  double x_ref = 0.0;
  mc::test::AllocationGuard guard;
  for (int k = 0; k < 3000; ++k) {
    x_ref += 200e-6 * 1e-4;
    c.set_reference({x_ref, 200e-6, 0.0});
    c.update(sensor.measure(test::model().slider_position(s)));
    for (int i = 0; i < 10; ++i) test::model().step(s, c.next_drive(1e-5));
  }
  EXPECT_EQ(guard.allocations(), 0u);
  EXPECT_GT(c.edges(), 0);  // the edges were exercised too
}

TEST(TrackingController, EmergencyStopDrivesZeroVolts) {
  TrackingController c(TrackingParams{}, test::model().params(), test::step_map());
  c.reset(0.0, 50.0);
  c.emergency_stop();
  EXPECT_EQ(c.next_drive(1e-5).end_V, 0.0);
  EXPECT_TRUE(c.stopped());
}

TEST(TrackingController, InvalidParamsAreRejected) {
  TrackingParams p;
  p.high_V = p.low_V + 5.0;
  EXPECT_THROW(p.validate(), InvalidParams);
  p = TrackingParams{};
  p.settle_s = p.catchup_s;
  EXPECT_THROW(p.validate(), InvalidParams);
  p = TrackingParams{};
  p.unload_V = 95.0;
  EXPECT_THROW(p.validate(), InvalidParams);
}

}  // namespace
}  // namespace mc::control
