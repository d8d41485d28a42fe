#pragma once
/// @file
/// A pick-and-place done by the visual servo alone, the stage's encoders off; the goal: the part
/// placed within 1 um (`microcobot vision pick-place`).
///
/// Sequence (one camera frame per step, as visual_servo_run.h's timeline):
///   1. approach: the tips (a template on a finger's tip) servoed by vision::VisualServo
///      over the part's centre, seen in the image (a template on the part), the gripper open to
///      `approach_opening_m` at `hover_m` above the part's top;
///   2. descend: Z down by hover + half the part's height (the tips at its mid-height);
///   3. grasp: the gripper closed to the opening that squeezes `grip_force_N` (its own drive);
///   4. lift by `lift_m`; a template taken on the held part (part and fingers move as one);
///   5. transport: that template servoed so that the part's centre lands on the target pixel;
///   6. lower by lift + `press_m` (the part touches down; the fingers slide on it), release,
///      retract by `retract_m`. Every axis ends holding.
///
/// What the sequence uses: the frames, the servo's calibration (the true one times a chosen
/// scale error), its own commands, and two clicks at the start (the tool point on the tips, the
/// target on the substrate). XY is the EncoderlessStage (open-loop stick-slip runs closed by the
/// servo). Z is the stage's Z axis under its own position controller and sensor, modelled as a
/// follower of the commanded height at `z_speed_m_s`: a stick-slip Z run open loop from the step
/// map (EncoderlessStage's way) missed 170 um descents by tens of percent in trials, enough to
/// drive the tips into the substrate, and nothing in a top view measures height finely enough to
/// close it (depth from focus is ~DOF/5, several um at 5x). `sensor: vision` is about XY. The
/// gripper is opened and closed by its own drive.
///
/// Where the part sits in the gripper: closing the jaw centres it along x on the tool point (a
/// symmetric gripper, microworld/pick_place_world.h), its y unchanged; so its centre after the
/// grasp is, in the image, the tool point's column and the part's row measured just before
/// closing (both from the frames). The simulation's ground truth (sliders, the part in the
/// world) renders the frames and judges the result, never steers.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "microcobot/vision/template_tracker.h"
#include "microcobot/vision/visual_servo.h"

namespace mc::studies {

enum class PickPlacePhase {
  kApproach,
  kDescend,
  kGrasp,
  kLift,
  kTransport,
  kLower,
  kRelease,
  kRetract,
  kDone
};
const char* to_string(PickPlacePhase p);

struct VisualPickPlaceParams {
  std::string scene = "pick-place";              ///< its part (size, adhesion); the start and target below
  std::string objective = "5x";                  ///< the part, its target and the tips in one field
  std::uint64_t seed = 1;                        ///< sensor noise
  int width_px = 0, height_px = 0;               ///< 0: the default sensor's
  Eigen::Vector2d target_offset_m{500e-6, 0.0};  ///< target - part's start (x, y)
  Eigen::Vector2d start_offset_m{0.0, 300e-6};   ///< tool point's start - part's start
  double hover_m = 20e-6;                        ///< tips above the part's top while approaching
  double approach_opening_m = 400e-6;            ///< clear of a 300 um part by 50 um per side
  double grip_force_N = 0.5e-3;                  ///< squeezed by closing the jaw
  double lift_m = 30e-6;                         ///< the part's bottom above the substrate
  double press_m = 10e-6;       ///< lowered this much further than lifted (touch-down despite Z's error)
  double retract_m = 50e-6;     ///< tips up after the release
  double z_speed_m_s = 0.4e-3;  ///< Z's moves (its controller's reference speed)
  int gripper_frames = 5;       ///< frames given to the gripper to close or open (its 2 ms lag)
  int settle_frames = 3;        ///< consecutive converged frames ending a servo phase
  int phase_frames = 200;       ///< a servo phase not converged in this many frames fails (holding)
  double calibration_scale_error = 0.0;  ///< x scale x (1 + e), y scale x (1 - e)
  double processing_latency_s = 10e-3;
  int template_px = 96;  ///< the tips' template
  vision::VisualServoParams servo;
  vision::TrackerParams tracker;

  void validate() const;
};

struct PickPlaceFrame {
  PickPlacePhase phase = PickPlacePhase::kApproach;
  double t_mid_s = 0.0;
  Eigen::Vector3d tool_m = Eigen::Vector3d::Zero();  ///< true, mid-exposure
  Eigen::Vector3d part_m = Eigen::Vector3d::Zero();  ///< true
  double u_px = 0.0, v_px = 0.0, confidence = 0.0;   ///< the servoed feature
  bool found = false;
  vision::ServoStatus status = vision::ServoStatus::kNoTarget;
  Eigen::Vector2d servo_error_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d velocity_m_s = Eigen::Vector2d::Zero();
  double grip_force_N = 0.0;  ///< the simulation's
};

struct VisualPickPlaceResult {
  std::vector<PickPlaceFrame> frames;
  bool completed = false;  ///< every phase done (else it stopped holding in `failed_phase`)
  PickPlacePhase failed_phase = PickPlacePhase::kDone;
  bool part_on_substrate = false;
  Eigen::Vector2d placement_error_m = Eigen::Vector2d::Zero();          ///< part's centre - target, at rest
  Eigen::Vector2d grasp_error_m = Eigen::Vector2d::Zero();              ///< tool - part at the grasp (true)
  bool xy_holding = false, z_holding = false, gripper_holding = false;  ///< at the end
  int approach_frames = 0, transport_frames = 0;
  double duration_s = 0.0;
  double pixel_m = 0.0;
  std::string first_png, grasp_png, last_png;  ///< overlays: feature (dark cross), its target (bright)
};

/// Runs the sequence. Throws InvalidParams / InvalidInput (bad parameters; the part, target or
/// start outside the field), ComputationFailed (the stick-slip model diverged).
VisualPickPlaceResult run_visual_pick_place(const VisualPickPlaceParams& params);

}  // namespace mc::studies
