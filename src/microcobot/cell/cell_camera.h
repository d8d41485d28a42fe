#pragma once
/// @file
/// The assembly cell's camera, the vision steps of the automatic task on rendered images: a microscope
/// pointed at the station the task looks at (the pin's slot, then its bore), whose frames are rendered from
/// the simulation's truth (imaging::Renderer, the sensor's noise included) and measured with what the cell is
/// told:
///
///   slot    the pin in its tray slot, before the approach: a model template (the pin alone at
///           its slot's nominal position and orientation, rendered without noise: the CAD-model
///           tracking of Tamadazte et al. 2010) found in the frame by vision::TemplateTracker with
///           its Euclidean warp: the pin's position and yaw, which the slot's play changed.
///   bore    the pin's bore (or a flat part's seat) before the transport, the station clear: a model
///           template (the bore alone where its drawing puts it, rendered without noise) found in
///           the frame focused on the substrate: where the bore really is (the plate's fixture
///           and machining: AssemblyBatchParams::bore_error_m), searched `bore_search_m` round
///           its drawing. A seat without a bore shows nothing to find: not looked for.
///   held    the pin in the fingers, over its bore, before the insertion: the fingers cover its
///           faces along their x (they squeezed it there, so it is centred along x), so its
///           offset along their y is measured on the two faces the fingers leave free: the
///           intensity profile along the fingers' y, averaged across a band between the fingers
///           (the frame sampled in the fingers' frame, bilinearly), its two edges located at the
///           gradient's extrema, refined by a parabola; the pin's centre is their midpoint.
///   align   the pin in the fingers over its bore (the visual servo in its look-and-move
///           form): the camera still where the bore look left it, one frame focused on the pin's
///           top; its faces the fingers leave free give its centre (along the fingers' y between
///           them, along their x below their ends), and vision::VisualServo's error e = s - s*
///           between its pixel and the pixel where the bore was seen, in metres through the
///           camera's map (L_e^+ = A^-1). Pin and bore are seen from the same camera pose, so an
///           error in where that pose is (view_error_m) cancels in e; the stage's own loop then
///           makes the displacement -e (look-and-move: Weiss, Sanderson & Neuman, IEEE J. Robotics
///           and Automation 3(5), 1987), and the task looks again until the servo says converged.
///   placed  the pin after the release, the fingers retracted: three frames focused at the height
///           a pin down in its bore has its top, and `focus_step_dof` depths of field either side;
///           the Tenengrad focus
///           measure's peak (vision::focus_peak) gives the top's height, the model template
///           the position. A pin on the rim (its top a bore's depth higher) or gone shows no peak
///           there.
///
/// The microscope is moved over each station (its view centred on the look's nominal point), as
/// a camera on its own positioner or one camera per station would be; the pixel <-> world map is
/// the objective's nominal one (the renderer's). Where the view really is differs from where the
/// cell believes it by `view_error_m` (per axis, drawn anew each time the microscope moves to
/// another station: its positioner's repeatability, the hand-eye calibration's drift): every
/// position a look reports is off by that much, the same for every look from one station. The truth renders
/// the frames and judges the estimates (CycleResult::look_error_m), never steers. Not real-time: CellCycle
/// calls it between runs of the loop, the task holding meanwhile (AssemblyTask::Status::kAwaitingLook).

#include <cstdint>
#include <memory>
#include <string>

#include <Eigen/Core>

#include "microcobot/core/rng.h"
#include "microcobot/platform/camera_scene.h"
#include "microcobot/platform/platform_config.h"

namespace mc::cell {

struct CellCameraParams {
  bool enabled = false;          ///< off: the nominal slot, the force-guarded search, a truth-based verify
  std::string objective = "5x";  ///< 1.1 um pixels: a 300 um pin and its 3-20 um play in one view
  int width_px = 0;              ///< the image's width; 0: the default sensor's (1280)
  int height_px = 0;             ///< its height; 0: the default sensor's (1024)
  /// Simulated time a look takes, the task holding: the exposure, the read-out and the measure
  /// (two frames at 30 frames/s).
  double look_s = 0.066;
  int seed = 1;  ///< the sensor's noise (each cycle and look its own frames)
  /// The model template's normalised correlation below which a pin is not seen.
  double min_confidence = 0.8;
  /// The held pin's band: this far inside its faces along the fingers' x (clear of the fingers).
  double band_inset_m = 20e-6;
  /// The placed look's frames: at the expected top and this many depths of field either side.
  double focus_step_dof = 2.0;
  /// How far from its drawing the bore look searches for the bore (3 of 10 um's standard deviations
  /// and some).
  double bore_search_m = 50e-6;
  /// The standard deviation, per axis, of where the microscope's view is from where the cell
  /// believes it, drawn each time it moves to another station (0: a calibrated, drift-free
  /// camera) [m].
  double view_error_m = 0.0;
  /// The insertion aligned by the visual servo (align looks until it converges: the pin and its bore
  /// in one camera pose) instead of one held look (the pin's offset in the fingers, the tool then
  /// placed by the stage's sensors over the bore as seen).
  bool servo = true;
  /// The servo's convergence: the pin's centre seen within this of its bore's (vision::VisualServo's
  /// converged_m: 0.3 um) [m].
  double servo_converged_m = 0.3e-6;

  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("objective", objective);
    v("width_px", width_px);
    v("height_px", height_px);
    v("look_s", look_s);
    v("seed", seed);
    v("min_confidence", min_confidence);
    v("band_inset_m", band_inset_m);
    v("focus_step_dof", focus_step_dof);
    v("bore_search_m", bore_search_m);
    v("view_error_m", view_error_m);
    v("servo", servo);
    v("servo_converged_m", servo_converged_m);
  }
  void validate() const;
};

/// One look's estimate, world frame.
struct PinSighting {
  bool found = false;
  Eigen::Vector3d part_m = Eigen::Vector3d::Zero();  ///< the pin's centre (z: from focus, placed only)
  double yaw_rad = 0.0;                              ///< slot: measured; else the expected one
  double confidence = 0.0;                           ///< the template's correlation (held: edge contrast)
  const char* reason = "";                           ///< why not found ("" when found)
  /// align: the servo's error, the pin's centre minus the bore's (world frame, from one camera
  /// pose), and whether it is within servo_converged_m.
  Eigen::Vector2d error_m = Eigen::Vector2d::Zero();
  bool converged = false;
};

/// What the cell knows of the pin (told, or measured by the task), for the looks.
struct PinModel {
  double side_m = 0.0;    ///< the pin's side (square)
  double height_m = 0.0;  ///< its height
};

class CellCamera {
 public:
  /// `config`'s world gives the scene (substrate, bore); the pin's pose comes with each look.
  /// `stream` picks the noise's stream (the part's index: each part its own frames). Throws
  /// mc::InvalidParams (parameters, objective).
  CellCamera(const CellCameraParams& params, const platform::PlatformConfig& config,
             std::uint64_t stream = 0);
  ~CellCamera();
  CellCamera(const CellCamera&) = delete;
  CellCamera& operator=(const CellCamera&) = delete;

  /// The pin in its slot, expected at `nominal_xy` turned by `nominal_yaw` (its top in focus).
  PinSighting look_slot(const platform::CameraScenePose& truth, const PinModel& pin,
                        const Eigen::Vector2d& nominal_xy, double nominal_yaw);
  /// The bore drawn at `drawn_xy`, turned by `yaw`: where it is (part_m's z 0: the rim).
  PinSighting look_bore(const platform::CameraScenePose& truth, const Eigen::Vector2d& drawn_xy, double yaw);
  /// The pin in the fingers: the tool point at `tool_m` (the stage's sensors), the fingers turned
  /// by `tool_yaw`; `top_z_m` the pin's top as the grasp left it (focus).
  PinSighting look_held(const platform::CameraScenePose& truth, const PinModel& pin,
                        const Eigen::Vector3d& tool_m, double tool_yaw, double top_z_m);
  /// The pin in the fingers over its bore: the camera over the bore's station `station_xy` (where
  /// the bore look looked: its drawing), the bore seen at `bore_seen_xy` from there; the tool
  /// point at `tool_m` (the stage's sensors), the fingers turned by `tool_yaw`, the pin's top at
  /// `top_z_m`. part_m: the pin's centre; error_m, converged: the servo's.
  PinSighting look_align(const platform::CameraScenePose& truth, const PinModel& pin,
                         const Eigen::Vector2d& station_xy, const Eigen::Vector2d& bore_seen_xy,
                         const Eigen::Vector3d& tool_m, double tool_yaw, double top_z_m);
  /// The pin after its release, expected down in its bore at `bore_xy` (turned by `bore_yaw`), its
  /// top at `top_z_m`; the camera over `station_xy` (the bore's station: the bore look's pose).
  PinSighting look_placed(const platform::CameraScenePose& truth, const PinModel& pin,
                          const Eigen::Vector2d& station_xy, const Eigen::Vector2d& bore_xy, double bore_yaw,
                          double top_z_m);

  int frames() const noexcept { return frames_; }
  const CellCameraParams& params() const noexcept { return p_; }
  /// Where the view is from where the cell believes it, at the present station.
  Eigen::Vector2d view_error() const noexcept { return view_error_; }

 private:
  struct Impl;
  /// The microscope over `centre` (believed): a new station draws a new view error. Returns where
  /// the view really is centred.
  Eigen::Vector2d move_to_station(const Eigen::Vector2d& centre);
  CellCameraParams p_;
  std::uint64_t seed_;
  std::unique_ptr<Impl> impl_;
  int frames_ = 0;
  Rng view_rng_;
  Eigen::Vector2d station_ = Eigen::Vector2d::Zero(), view_error_ = Eigen::Vector2d::Zero();
  bool at_station_ = false;
};

/// The truth the camera renders: the slave's tips (the sliders, not the sensors), the gripper, the
/// pin.
platform::CameraScenePose truth_pose(const platform::Platform& p);

}  // namespace mc::cell
