// The visual servo's law on synthetic features: converges on an ideal plant,
// with a 5 % calibration error too; predicts the motion made during the latency; holds when the
// target is lost or the frame stale; steps without allocating; refuses bad gains and targets in
// one line. The closed loop on rendered frames and the stick-slip stage is
// tests/studies/visual_servo_run_test.cc.

#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/vision/visual_servo.h"
#include "support/counting_allocator.h"

namespace mc::vision {
namespace visual_servo_test {

constexpr double kPixel = 0.53e-6;  // 10x
constexpr int kW = 1280, kH = 1024;

AffineMap true_map() {
  AffineMap m;
  m.A << 1.0 / kPixel, 0.0, 0.0, -1.0 / kPixel;
  m.b << 640.0, 512.0;
  return m;
}

// An ideal stage (moves exactly as commanded) seen through `truth`, the servo believing
// `believed`; frames every T, the command issued `latency` after mid-exposure. Returns the stage
// error [m] after `frames` frames.
double ideal_loop(const AffineMap& truth, const AffineMap& believed, int frames, double latency_s,
                  bool predict, double gain = 10.0) {
  VisualServoParams p;
  p.gain_per_s = gain;
  p.deadband_m = 0.0;
  VisualServo servo(p, believed, kW, kH);
  const Eigen::Vector2d goal(10e-6, -20e-6);
  const Eigen::Vector2d target = truth.pixel_of(goal);
  servo.set_target(target.x(), target.y());
  Eigen::Vector2d x = goal + Eigen::Vector2d(50e-6, 0.0);
  Eigen::Vector2d v = Eigen::Vector2d::Zero();
  const double T = 1.0 / 30.0, dt = 1e-4;
  double t = 0.0;
  Eigen::Vector2d seen_at = x;
  double t_mid = 0.0;
  for (int k = 0; k < frames; ++k) {
    // mid-exposure
    seen_at = x;
    t_mid = t;
    // latency: the last command keeps acting
    for (double s = 0.0; s < latency_s - 1e-12; s += dt) x += v * dt;
    t += latency_s;
    ServoFeature f;
    const Eigen::Vector2d px = truth.pixel_of(seen_at);
    f.u_px = px.x();
    f.v_px = px.y();
    f.found = true;
    f.t_mid_exposure_s = predict ? t_mid : t;  // without prediction: the frame taken as now
    v = servo.step(f, t).velocity_m_s;
    for (double s = 0.0; s < T - latency_s - 1e-12; s += dt) x += v * dt;
    t += T - latency_s;
  }
  return (x - goal).norm();
}

TEST(VisualServo, ConvergesOnAnIdealStageAndWithAFivePercentCalibrationError) {
  const AffineMap truth = true_map();
  EXPECT_LT(ideal_loop(truth, truth, 30, 0.02, true), 1e-9);
  for (double e : {0.05, -0.05}) {
    AffineMap off = truth;
    off.A(0, 0) *= 1.0 + e;
    off.A(1, 1) *= 1.0 - e;
    EXPECT_LT(ideal_loop(truth, off, 30, 0.02, true), 1e-8) << "calibration error " << e;
  }
  // Rotated 3 degrees as well: still converges.
  AffineMap turned = truth;
  const double a = 3.0 * M_PI / 180.0;
  turned.A = truth.A * Eigen::Rotation2Dd(a).toRotationMatrix();
  EXPECT_LT(ideal_loop(truth, turned, 40, 0.02, true), 1e-8);
}

TEST(VisualServo, PredictingTheMotionDuringTheLatencyKeepsAHighGainStable) {
  const AffineMap truth = true_map();
  // 30 ms of latency (of a 33 ms frame) at lambda = 45 1/s: blind to its own motion the loop
  // overshoots and grows;
  // with the prediction it converges.
  const double with = ideal_loop(truth, truth, 60, 0.03, true, 45.0);
  const double without = ideal_loop(truth, truth, 60, 0.03, false, 45.0);
  EXPECT_LT(with, 1e-9);
  EXPECT_GT(without, 1e-6);
}

TEST(VisualServo, HoldsWhenTheTargetIsLostOrTheFrameStale) {
  VisualServo servo({}, true_map(), kW, kH);
  servo.set_target(600.0, 500.0);
  ServoFeature f{700.0, 500.0, true, 0.0};
  ServoCommand c = servo.step(f, 0.02);
  EXPECT_EQ(c.status, ServoStatus::kMoving);
  EXPECT_LT(c.velocity_m_s.x(), 0.0);  // the feature is right of the target: move left
  f.found = false;
  c = servo.step(f, 0.05);
  EXPECT_EQ(c.status, ServoStatus::kHoldLost);
  EXPECT_EQ(c.velocity_m_s.norm(), 0.0);
  f.found = true;
  f.t_mid_exposure_s = 0.0;
  c = servo.step(f, 1.0);  // a second-old frame
  EXPECT_EQ(c.status, ServoStatus::kHoldStale);
  EXPECT_EQ(c.velocity_m_s.norm(), 0.0);
  f.u_px = std::numeric_limits<double>::quiet_NaN();
  f.t_mid_exposure_s = 0.99;
  EXPECT_EQ(servo.step(f, 1.0).status, ServoStatus::kHoldLost);
  // Found again: moves.
  f.u_px = 650.0;
  EXPECT_EQ(servo.step(f, 1.0).status, ServoStatus::kMoving);
}

TEST(VisualServo, StepsWithoutAllocating) {
  VisualServo servo({}, true_map(), kW, kH);
  servo.set_target(600.0, 500.0);
  ServoFeature f{700.0, 450.0, true, 0.0};
  mc::test::AllocationGuard guard;
  double t = 0.0;
  for (int k = 0; k < 1000; ++k) {
    f.t_mid_exposure_s = t;
    t += 0.02;
    const ServoCommand c = servo.step(f, t, 0.013);
    f.u_px += 0.5 * c.velocity_m_s.x() / kPixel * 0.013;
    t += 0.013;
  }
  EXPECT_EQ(guard.allocations(), 0u);
}

TEST(VisualServo, BadGainsAndTargetsAreRefusedInOneLine) {
  VisualServoParams p;
  p.gain_per_s = std::numeric_limits<double>::quiet_NaN();
  try {
    VisualServo s(p, true_map(), kW, kH);
    FAIL() << "a NaN gain was accepted";
  } catch (const InvalidParams& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("gain_per_s"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos);
  }
  p.gain_per_s = -1.0;
  EXPECT_THROW(VisualServo(p, true_map(), kW, kH), InvalidParams);
  AffineMap flat;
  flat.A << 1.0, 2.0, 2.0, 4.0;  // the stage's axes seen parallel
  EXPECT_THROW(VisualServo({}, flat, kW, kH), InvalidParams);
  VisualServo servo({}, true_map(), kW, kH);
  try {
    servo.set_target(1500.0, 20.0);
    FAIL() << "a target outside the frame was accepted";
  } catch (const InvalidInput& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("1500"), std::string::npos) << what;
    EXPECT_NE(what.find("1280x1024"), std::string::npos) << what;
  }
  EXPECT_THROW(servo.set_target(std::numeric_limits<double>::quiet_NaN(), 1.0), InvalidInput);
  EXPECT_FALSE(servo.has_target());
  // Without a target: no motion.
  EXPECT_EQ(servo.step(ServoFeature{1.0, 1.0, true, 0.0}, 0.01).status, ServoStatus::kNoTarget);
}

}  // namespace visual_servo_test
}  // namespace mc::vision
