#pragma once
/// @file
/// The stage positioned by what the camera sees (`stage.xy_sensor: vision`):
/// on the camera thread, each frame's gripper tips are tracked (vision/template_tracker.h) and
/// the visual servo (vision/visual_servo.h, v = -lambda L+ e with the Smith predictor on its own
/// commands) turns the distance to the operator's goal into a stage velocity for an interval;
/// the loop plays it as open-loop runs on x and y (Platform::command_open_loop_velocity). The
/// axes' position sensors are never read: where the tool is comes from the image alone. The two
/// finger tips are tracked apart, each by the finger's outer half (finger_templates.h: a gripped
/// part never enters it); each, with the gripper's opening (its own sensor), says where the tool
/// point is, and the tool point is the mean of the tips that agree with where the commands put it
/// (within the tracker's search margin): a tip leaving the view, or a tracker that lost its tip
/// and found its twin, the other finger, by a whole-frame search, is left out. Two tips that
/// disagree by more than a pixel: one holds something that does not move with it (a part's edge
/// under its template, 3 um off at 5x), and the better-matching tip alone gives the tool point.
/// The rotary axis turns the fingers about the tool point: while they turn the stage holds; still
/// for 3 frames at a new yaw, the tips are taught again there and tracked turned.
///
///   loop (1 kHz) --goal (world or pixel), deadman--> atomics --> camera thread: on_frame()
///   camera thread --PositionerCommand--> returned to the caller, who rings it to the loop
///
/// The pixel <-> stage map is the objective's calibration (`camera.calibrations`, measured by
/// `microcobot vision calibrate --save`), or without one the objective's nominal map (its pixel
/// size, image axes along the stage's, rows down): the servo converges with a map a few per cent
/// off (docs/benchmarks.md). Stage coordinates are the axes' positions from the stage's home.
///
/// Timing: a stick-slip slider seen during a sawtooth period is off by up to the piezo's stroke,
/// so each run is timed to end before the next exposure that starts after it could begin, and a
/// frame exposed while a run may still play is tracked but not servoed on. The templates are
/// taught on the first frame where both tips are expected inside the image (the stage starts at
/// its home), again after an objective change (at where the tool was last seen), and again when
/// both were lost for a second. A lost tool, a released deadman, or no
/// goal: no command (the axes rest at 0 V). Frames are converted and tracked here, on the camera
/// thread, never on the loop.

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <mutex>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "microcobot/devices/camera_frame.h"
#include "microcobot/perception/camera_map.h"
#include "microcobot/perception/vision_positioner_params.h"
#include "microcobot/vision/affine_calibration.h"
#include "microcobot/vision/template_tracker.h"
#include "microcobot/vision/visual_servo.h"

namespace mc::perception {

/// What the loop is asked to play: the stage's (x, y) velocity from `t_issue_s` for `interval_s`.
struct PositionerCommand {
  Eigen::Vector2d velocity_m_s = Eigen::Vector2d::Zero();
  double interval_s = 0.0;
  double t_issue_s = 0.0;  ///< the positioner's clock (the frames' live time)
};

/// What the positioner last saw and did, for the console and the tests.
struct PositionerStatus {
  bool taught = false;  ///< the tips' template is taken
  bool found = false;   ///< ...and found in the last frame
  bool has_goal = false;
  std::string state = "waiting";  ///< waiting, moving, converged, hold-lost, hold-stale, hold (fingers
                                  ///< turning), no-goal, no-deadman, error
  std::string error;              ///< why the goal was refused or the template could not be taken
  double tool_u_px = 0.0, tool_v_px = 0.0;  ///< where the tool point is seen
  double goal_u_px = 0.0, goal_v_px = 0.0;  ///< where it is sent (the tool point's pixel)
  double error_m = 0.0;                     ///< the servo's predicted distance to the goal
  /// The stage rests at the goal (the servo within its window, no run asked) until the error
  /// leaves the converged window.
  bool in_position = false;
  double confidence = 0.0;  ///< the tracker's correlation
  /// The tool's stage position from the image (m, from the stage's home) and the map's pixel size.
  double stage_x_m = 0.0, stage_y_m = 0.0;
  double m_per_px = 0.0;
  bool calibrated = false;  ///< the objective's measured calibration is used (else the nominal map)
  std::uint64_t frames = 0, commands = 0;
};

class VisionPositioner {
 public:
  /// `rig` gives the camera (sensor, objectives, calibrations, view centre), the stage's home and
  /// the fingers' width. Throws mc::InvalidParams.
  explicit VisionPositioner(const CameraRig& rig, const VisionPositionerParams& params = {});

  /// The operator's goal for the tool point: a world point (x, y) or a pixel of the image.
  /// Any thread; lock-free (the loop calls them). The latest wins.
  void request_goal_world(double x_m, double y_m) noexcept;
  void request_goal_pixel(double u_px, double v_px) noexcept;
  void clear_goal() noexcept;
  /// Whether the loop would play a run now (the controlling operator's deadman held, fresh
  /// commands, no fault). Any thread; lock-free.
  void set_enabled(bool enabled) noexcept { enabled_.store(enabled, std::memory_order_relaxed); }

  /// One frame (camera thread): `t_mid_s` its mid-exposure and `now()` the time, on one clock.
  /// The clock is read once the tips are tracked: tracking takes milliseconds (tens when the
  /// camera thread shares its core), and a run timed from before it would reach the loop after
  /// its end. The command to ring to the loop, if any. Never throws: a goal outside the image or
  /// a template that cannot be taken is reported in the status.
  std::optional<PositionerCommand> on_frame(const devices::CameraFrame& frame, double t_mid_s,
                                            const std::function<double()>& now);

  /// A new scene: the stage back at its home, the template to be taught again, no goal. Any
  /// thread; taken at the next frame.
  void reset() noexcept {
    clear_goal();
    reset_.store(true, std::memory_order_release);
  }

  PositionerStatus status() const;
  /// The map used with objective `i` (the measured calibration, or the nominal one).
  vision::AffineMap map_for(int objective, bool* calibrated = nullptr) const;

 private:
  void switch_objective(int objective, int width_px, int height_px);
  void take_goal(PositionerStatus& st);
  void publish(const PositionerStatus& st);

  CameraRig rig_;
  VisionPositionerParams p_;
  Eigen::Vector2d home_xy_m_;
  // Goal requests (any thread -> camera thread).
  std::atomic<std::uint64_t> goal_seq_{0};
  std::atomic<int> goal_kind_{0};  // 0 none, 1 world, 2 pixel
  std::atomic<double> goal_a_{0.0}, goal_b_{0.0};
  std::atomic<bool> enabled_{false}, reset_{false};
  // Camera thread only.
  std::uint64_t taken_goal_seq_ = 0;
  int objective_ = -1, width_ = 0, height_ = 0;
  vision::AffineMap map_;
  bool calibrated_ = false;
  std::optional<vision::VisualServo> servo_;
  /// Teaches the tips' templates around the tool point `tool_px`: each whose template lies in the
  /// image (false: neither).
  bool teach(const Eigen::Vector2d& tool_px, double opening_m, PositionerStatus& st);
  /// Teaches tip `k` (0 left, 1 right) around `tool_px`; false with `why` when it cannot.
  bool teach_tip(std::size_t k, const Eigen::Vector2d& tool_px, double opening_m, std::string& why);
  /// From the tool point to tip `k` (pixels), the fingers `opening_m` apart at taught_yaw_.
  Eigen::Vector2d tip_step_px(std::size_t k, double opening_m) const;
  std::array<bool, 2> tip_taught_{false, false};
  double taught_yaw_ = 0.0;  ///< the fingers' yaw the tips are taught and tracked at (rad)
  double last_frame_yaw_ = std::numeric_limits<double>::quiet_NaN();
  int still_frames_ = 0;  ///< frames in a row the fingers have not turned

  std::array<vision::TemplateTracker, 2> trackers_;  ///< the left and the right tip
  imaging::Frame frame_;
  bool taught_ = false, has_goal_ = false;
  int lost_frames_ = 0;
  /// Template centre - the tip's point, per tip (taught); the tips lie at the tool point
  /// -+ opening / 2 along the fingers' x (stage x turned by taught_yaw_).
  std::array<Eigen::Vector2d, 2> tip_offset_px_{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  Eigen::Vector2d tool_px_ = Eigen::Vector2d::Zero();   ///< the tool point last seen
  Eigen::Vector2d stage_m_ = Eigen::Vector2d::Zero();   ///< ... as a stage position
  Eigen::Vector2d moved_px_ = Eigen::Vector2d::Zero();  ///< commanded motion since the last frame
  double run_end_s_ = -1e9;                             ///< the last run may play until then
  int converged_frames_ = 0;                            ///< servoed frames in a row within the window
  int hunt_frames_ = 0;  ///< servoed frames in a row within the converged window
  bool in_position_ = false;
  std::uint64_t frames_ = 0, commands_ = 0;
  // Status (camera thread -> any thread).
  mutable std::mutex status_mutex_;
  PositionerStatus status_;
};

}  // namespace mc::perception
