#pragma once
/// @file
/// The grip force measured by vision, live (thesis Fig. 1.5, after Greminger
/// & Nelson, IEEE TPAMI 26(3), 2004): on the camera thread, each frame's two finger tips are
/// tracked and the distance between them, against the opening the gripper's drive puts the
/// fingers at without a load, is the fingers' deflection; times their stiffness it is the force
/// (microworld/piezo_gripper.h):
///
///     gap  = g_ref + ((p_right - p_left) . e_x - d_ref) / s      [m]
///     F    = k (gap - o_free) / 2                                 [N]
///
/// with p_* the tips' template centres [px], e_x the stage's x axis in the image and s its scale
/// [px/m] (the objective's calibration, or its nominal map: camera_map.h), o_free the drive's
/// free opening (Gripper::free_opening_m: its open-loop model), k the finger stiffness, and
/// (g_ref, d_ref) a reference: the tare, taken with nothing between the fingers (g_ref = o_free
/// then, d_ref the mean over the tare's first 15 frames), or, after an objective change or a turn of
/// the fingers, the gap last measured before it.
/// With the fingers turned by the rotary axis (`tool_yaw_rad`), e_x and the tips' half gaps turn with
/// them: the tips are taught again at each new yaw, once still for 3 frames, the gap chained from
/// before the turn while a part is held (the drive's opening when nothing was: a fresh tare), unless
/// the drive moved meanwhile (then a tare is asked for); while they turn, no force.
/// The gap is a difference of two tips, so the stage's motion cancels: the gauge needs no
/// stage sensor, only where to look (the tips' predicted pixels) and the scale.
///
/// The contact force: a lateral force on the fingers along their closing axis bends both tips
/// together (microworld/pick_place_world.h: common mode, 2 k), so their midpoint leaves the tool
/// point the stage's x, y sensors give, through the map:
///
///     b    = b_ref + ((m - t) . e_x - c_ref) / s      [m]     m = (p_left + p_right) / 2 - offsets
///     F_c  = 2 k b                                     [N]     (signed, along e_x)
///
/// with t the tool point's pixel and (b_ref, c_ref) the reference: the tare's (nothing touches the
/// fingers: b_ref = 0, c_ref the mean over its first 15 frames) or, chained, the bend last measured.
/// The midpoint is measured against the stage's motion since the tare, so the map's error e adds
/// 2 k e |motion| (10 uN for 0.1 % over 100 um): a contact is read near where the gauge was
/// tared. Without stage sensors (the vision positioner's tool point is the tips themselves) there
/// is no contact force (NaN).
///
/// The offline estimator (vision/finger_force.h, `microcobot vision force`) fits the opening's
/// scale on four unloaded openings with a fixed stage; live, the stage moves and the operator
/// does not sweep the gripper, so the scale is the map's: its error e scales the deflection
/// (F is off by e F plus k e (o_tare - o) / 2, 5 uN for a 0.2 % map and 100 um of closing).
///
/// Where the tips are looked for: the tool point (the stage's measured position through the
/// map; without x, y sensors the vision positioner's tool point, or while it has lost the tool
/// (a gripped part under its templates) the one the gauge's own tips gave last) plus half the
/// gap predicted from the drive: o_free, or, while a part holds the fingers apart, the larger of
/// o_free and the last gap (a part blocks closing, not opening). A tip lost, or two matches that
/// do not look like the two tips (the right one left of the left one, rows apart): no force
/// that frame (NaN), and a status that says why. Not thread-safe except where noted: one gauge
/// per camera thread; OpenCV allocates in the trackers, never on the loop.

#include <array>
#include <atomic>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "microcobot/devices/camera_frame.h"
#include "microcobot/perception/camera_map.h"
#include "microcobot/perception/vision_grip_force_params.h"
#include "microcobot/vision/affine_calibration.h"
#include "microcobot/vision/template_tracker.h"

namespace mc::perception {

/// What the gauge last measured, for the console, the telemetry and the tests.
struct VisionGripStatus {
  /// untared (waiting for a tare), measuring, lost (a tip not found: no force), error (the tare
  /// could not be taken, or the gripper's drive has no model of its free opening).
  std::string state = "untared";
  std::string error;  ///< why, for lost and error
  bool tared = false;
  double grip_force_N = std::nan("");  ///< NaN when not measured in the last frame
  double gap_m = std::nan("");         ///< the tips' distance as seen
  double free_opening_m = 0.0;         ///< the drive's opening without a load, at the frame
  /// The lateral contact force along the fingers' closing axis (their yaw: +x at 0), signed
  /// [N]; NaN when not measured (no stage sensor, or the frame not measured).
  double contact_force_N = std::nan("");
  double bend_m = std::nan("");  ///< the tips' common-mode bend it comes from
  double confidence = 0.0;       ///< the lower of the two tips' correlations
  double t_mid_s = 0.0;          ///< the frame's mid-exposure (loop time)
  std::uint64_t frames = 0, tares = 0;
};

class VisionGripForce {
 public:
  /// `rig` gives the camera (objectives, calibrations, view centre), the stage's home and the
  /// fingers' width and stiffness; `params` the gauge's (configuration key vision_force). Throws
  /// mc::InvalidParams.
  VisionGripForce(const CameraRig& rig, const VisionGripForceParams& params);

  /// Tare at the next frame: the operator says nothing is between the fingers. Any thread.
  void request_tare() noexcept { tare_.store(true, std::memory_order_release); }
  /// A new scene: the reference forgotten, tared again at its first frame when tare_at_start.
  /// Any thread.
  void reset() noexcept { reset_.store(true, std::memory_order_release); }

  /// Where the caller says the tool point is in a frame.
  struct ToolHint {
    std::optional<Eigen::Vector2d> pixel;  ///< seen there (the vision positioner's tool point)
    bool stage_sensed = true;              ///< else: the frame's stage position (x, y sensors)
  };
  /// One frame (camera thread). Without a pixel and without stage sensors (the positioner lost
  /// the tool), the tips are looked for where the gauge saw them last. Never throws: what went
  /// wrong is in the status.
  const VisionGripStatus& on_frame(const devices::CameraFrame& frame, const ToolHint& hint);

  /// The last status (any thread: a copy under a lock that the loop never takes).
  VisionGripStatus status() const;

 private:
  /// `bend_m`: the fingers' common-mode bend at this frame (0 at a tare).
  bool teach(const Eigen::Vector2d& tool_px, double gap_m, double free_opening_m, double bend_m);
  /// e_x and its scale for the fingers at `yaw_rad` (the map's and the yaw's).
  void set_directions(double yaw_rad);
  Eigen::Vector2d tip_step_px(int side, double gap_m) const;
  void publish();

  CameraRig rig_;
  VisionGripForceParams p_;
  double stiffness_N_m_;
  std::atomic<bool> tare_{false}, reset_{true};
  // Camera thread only.
  std::array<vision::TemplateTracker, 2> trackers_;  ///< the left and the right tip
  imaging::Frame frame_;
  vision::AffineMap map_;
  int objective_ = -1, width_ = 0, height_ = 0;
  Eigen::Vector2d e_x_ = Eigen::Vector2d::UnitX();  ///< stage x in the image (unit)
  double scale_px_m_ = 1.0;                         ///< its px per metre
  double yaw_ = 0.0;                                ///< the fingers' yaw e_x is turned by
  double last_frame_yaw_ = std::nan("");            ///< the previous frame's (turning or still)
  int still_frames_ = 0;                            ///< frames in a row the yaw stayed still
  int tare_frames_ = 0;         ///< frames averaged into the tare's reference (0: not refining)
  double tare_d_sum_px_ = 0.0;  ///< their tips' distances
  double tare_c_sum_px_ = 0.0;  ///< their midpoints' offsets from the tool point along e_x
  double measured_free_opening_m_ = std::nan("");  ///< the drive's at the last measurement
  bool taught_ = false, loaded_ = false;
  bool auto_tare_ = false;  ///< the scene's tare (tare_at_start), tried until it is taken
  /// Template centre - (tool point + the tip's half gap), per tip, as taught.
  std::array<Eigen::Vector2d, 2> offset_px_{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  double ref_gap_m_ = 0.0, ref_d_px_ = 0.0;   ///< (g_ref, d_ref)
  double ref_bend_m_ = 0.0, ref_c_px_ = 0.0;  ///< (b_ref, c_ref)
  double last_gap_m_ = 0.0, last_bend_m_ = 0.0;
  Eigen::Vector2d last_tool_px_ = Eigen::Vector2d::Zero();  ///< the tool point the tips say
  VisionGripStatus st_;
  mutable std::mutex status_mutex_;
  VisionGripStatus published_;
};

}  // namespace mc::perception
