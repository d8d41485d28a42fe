// Visual servoing with the stage's encoders off, closed on rendered frames:
// the tips brought over the part from 50 um away within 30 frames to <= 0.3 um, with a 5 %
// calibration error too, holding still while the gripper is hidden. Starts from the validation
// set (start seed 2; the gain was chosen on start seed 1).

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/studies/visual_servo_run.h"

namespace mc::studies {
namespace visual_servo_run_test {

ServoRunParams start(double angle_rad, std::uint64_t seed) {
  ServoRunParams p;
  p.width_px = p.height_px = 512;  // the physics does not depend on the pixel count
  p.start_offset_m = 50e-6 * Eigen::Vector2d(std::cos(angle_rad), std::sin(angle_rad));
  p.seed = seed;
  p.max_frames = 32;
  return p;
}

TEST(VisualServoRun, ReachesThePartFrom50umWithin30FramesEncodersOff) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI);
  for (int s = 0; s < 3; ++s) {
    for (double error : {0.0, 0.05, -0.05}) {
      ServoRunParams p = start(angle(rng), 2000 + static_cast<std::uint64_t>(s));
      p.calibration_scale_error = error;
      const ServoRunResult r = run_visual_servo(p);
      EXPECT_LE(r.final_error_m.norm(), 0.3e-6) << "start " << s << ", calibration error " << error;
      EXPECT_GE(r.converged_frame, 0) << "start " << s << ", calibration error " << error;
      EXPECT_LE(r.converged_frame, 30) << "start " << s << ", calibration error " << error;
      EXPECT_GT(r.frames.front().true_error_m.norm(), 49e-6);
    }
  }
}

TEST(VisualServoRun, HoldsWhileTheTargetIsLostAndResumesWhenItIsBack) {
  ServoRunParams p = start(0.7, 2100);
  p.occlude_from = 3;
  p.occlude_to = 9;
  p.max_frames = 40;
  const ServoRunResult r = run_visual_servo(p);
  // Moving before, holding while hidden: the stage stays where it was (no encoder, no feature).
  EXPECT_GT((r.frames[1].true_error_m - r.frames[3].true_error_m).norm(), 1e-6);
  for (int k = 3; k < 9; ++k) {
    const ServoFrame& f = r.frames[static_cast<std::size_t>(k)];
    EXPECT_FALSE(f.found) << "frame " << k;
    EXPECT_EQ(f.status, vision::ServoStatus::kHoldLost) << "frame " << k;
    EXPECT_EQ(f.velocity_m_s.norm(), 0.0);
    if (k > 3) {
      EXPECT_LT((f.true_error_m - r.frames[3].true_error_m).norm(), 0.05e-6) << "frame " << k;
    }
  }
  EXPECT_GT(r.frames[8].true_error_m.norm(), 5e-6);  // not there yet when it was hidden
  EXPECT_TRUE(r.frames[9].found);                    // found again where it was left
  EXPECT_LE(r.final_error_m.norm(), 0.3e-6);
}

TEST(VisualServoRun, BadParametersAreRefusedInOneLine) {
  ServoRunParams p = start(0.0, 1);
  p.servo.gain_per_s = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(run_visual_servo(p), InvalidParams);
  p = start(0.0, 1);
  p.template_px = 4;  // an empty-ish ROI
  EXPECT_THROW(run_visual_servo(p), InvalidParams);
  p = start(0.0, 1);
  p.start_offset_m = {400e-6, 0.0};  // the tool outside the 512 px view: its template too
  EXPECT_THROW(run_visual_servo(p), InvalidInput);
}

}  // namespace visual_servo_run_test
}  // namespace mc::studies
