#pragma once
/// @file
/// A visual servoing run with the stage's encoders off (`microcobot vision
/// servo`): the gripper's tips brought over the pick-and-place part by vision::VisualServo, the
/// stage an EncoderlessStage (stick-slip axes driven open loop), the camera a imaging::Renderer
/// of the scene at each frame's mid-exposure, the tips followed by a vision::TemplateTracker.
///
/// What the loop uses: the frames (tracked), the servo's calibration (the true one scaled by a
/// chosen error) and its own past commands. What only the simulation knows: the sliders' true
/// positions (the scene is rendered from them and the result judged against them) and, once at
/// the start, where the tool point lies in the template and where the part's centre is in the
/// image (what an operator's two clicks give: on the tips, on the part).
///
/// Timeline of frame k (period T = 1 / frame rate): exposure [kT, kT + t_exp], rendered at the
/// slider positions of mid-exposure with the mean velocity over the exposure (motion blur);
/// tracked and the command issued at kT + t_exp + latency; the command holds for T.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "microcobot/vision/template_tracker.h"
#include "microcobot/vision/visual_servo.h"

namespace mc::studies {

struct ServoRunParams {
  std::string scene = "pick-place";
  std::string objective = "10x";
  std::uint64_t seed = 1;           ///< sensor noise
  int width_px = 0, height_px = 0;  ///< 0: the default sensor's
  /// Where the tool starts, relative to the goal (over the part's centre) [m].
  Eigen::Vector2d start_offset_m{50e-6, 0.0};
  /// The servo's calibration error: its map's x scale x (1 + e), y scale x (1 - e).
  double calibration_scale_error = 0.0;
  double hover_m = 20e-6;               ///< tips above the part's top
  double processing_latency_s = 10e-3;  ///< end of exposure -> command
  int max_frames = 60;
  int template_px = 96;
  /// Frames [occlude_from, occlude_to) rendered without the gripper (a lost target).
  int occlude_from = -1, occlude_to = -1;
  vision::VisualServoParams servo;
  vision::TrackerParams tracker;

  void validate() const;
};

struct ServoFrame {
  double t_mid_s = 0.0;
  Eigen::Vector2d true_error_m = Eigen::Vector2d::Zero();   ///< tool - goal at mid-exposure
  Eigen::Vector2d servo_error_m = Eigen::Vector2d::Zero();  ///< the servo's predicted error
  Eigen::Vector2d velocity_m_s = Eigen::Vector2d::Zero();   ///< commanded
  double u_px = 0.0, v_px = 0.0, confidence = 0.0;
  bool found = false;
  vision::ServoStatus status = vision::ServoStatus::kNoTarget;
  int periods_x = 0, periods_y = 0;  ///< the open-loop runs asked
};

struct ServoRunResult {
  std::vector<ServoFrame> frames;
  double pixel_m = 0.0;
  Eigen::Vector2d target_px = Eigen::Vector2d::Zero();
  Eigen::Vector2d final_error_m = Eigen::Vector2d::Zero();  ///< at rest after the last frame
  /// First frame from which the true error stays <= converged_m to the end (-1: never).
  int converged_frame = -1;
  double converged_m = 0.3e-6;
  std::string first_png, last_png;  ///< the first and last frames with the target marked
};

/// Runs the loop. Throws InvalidParams / InvalidInput (bad parameters, a template or target
/// outside the frame), ComputationFailed (the stick-slip model diverged).
ServoRunResult run_visual_servo(const ServoRunParams& params);

}  // namespace mc::studies
