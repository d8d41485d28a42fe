#pragma once
/// @file
/// The one description of the platform: loop rates, the teleoperation scales and
/// limits, the slave stage's controller and sensors, the masters' models, the microworld, and
/// optionally a stick-slip parameter file (as `microcobot stickslip params` prints it). The
/// built-in default is the platform of the main scenario; a YAML file overrides any key:
///
///     loop: {base_rate_Hz: 10000, slave_divisor: 10}
///     teleop: {motion_scale: 0.01, force_scale: 10000}
///     stickslip_params_file: axis.yaml      # relative to the configuration file
///     devices: {driver: lab-bench, connection: "192.168.10.5:5000"}   # docs/hardware.md
///
/// Unknown keys, wrong types and values out of range are one-line errors naming the key.

#include <filesystem>
#include <string>

#include "microcobot/devices/camera_device.h"
#include "microcobot/devices/parallel_positioner_controller.h"
#include "microcobot/haptics/dual_stage_plant.h"
#include "microcobot/haptics/pantograph.h"
#include "microcobot/haptics/render_pipeline.h"
#include "microcobot/microworld/optical_trap.h"
#include "microcobot/microworld/pick_place_world.h"
#include "microcobot/microworld/tip_alignment.h"
#include "microcobot/motion/parallel_stage.h"
#include "microcobot/motion/position_controller.h"
#include "microcobot/motion/position_sensor.h"
#include "microcobot/motion/rotary_axis.h"
#include "microcobot/motion/step_map.h"
#include "microcobot/motion/tracking_controller.h"
#include "microcobot/perception/camera_map.h"
#include "microcobot/perception/vision_grip_force_params.h"
#include "microcobot/perception/vision_positioner_params.h"
#include "microcobot/stickslip/stickslip_params.h"
#include "microcobot/teleop/teleoperation.h"
#include "microcobot/tweezers/teletweez.h"

namespace mc::platform {

struct LoopParams {
  double base_rate_Hz = 1.0e4;  ///< haptic path (thesis §3.3.1: 10 kHz)
  int slave_divisor = 10;       ///< slave control every 10 ticks: 1 kHz
  int operator_divisor = 10;    ///< the (scripted) operator acts at 1 kHz
  int telemetry_divisor = 10;   ///< telemetry recorded at 1 kHz
  int watchdog_ticks = 5;       ///< masters stale after this many ticks without a fresh reading
  bool realtime = false;        ///< pace to the wall clock (else as fast as possible)
  /// Real time: the core the loop's thread is pinned to, the process's other threads kept off it
  /// (-1: not pinned). With `isolcpus=` or a cpuset keeping other processes off that core too,
  /// the tick no longer pays for the servers' cache and TLB traffic (docs/hardware.md).
  int cpu = -1;

  template <class V>
  void visit(V& v) {
    v("base_rate_Hz", base_rate_Hz);
    v("slave_divisor", slave_divisor);
    v("operator_divisor", operator_divisor);
    v("telemetry_divisor", telemetry_divisor);
    v("watchdog_ticks", watchdog_ticks);
    v("realtime", realtime);
    v("cpu", cpu);
  }
  void validate() const;
  double period_s() const { return 1.0 / base_rate_Hz; }
  double slave_rate_Hz() const { return base_rate_Hz / slave_divisor; }
};

struct StageParams {
  motion::PositionControlParams control = default_control();
  /// The axes follow the teleoperation target with the tracking controller
  /// (reference-phased sawtooth, updated at every loop tick on the axis positions; the 1 kHz target
  /// is extrapolated with its velocity) instead of the hybrid position controller (false).
  bool tracking_enabled = true;
  motion::TrackingParams tracking = default_tracking();
  motion::PositionSensorParams sensor;
  /// What positions the stage in the plane: "encoders", the axes' position
  /// sensors closing the stage controller's loop, or "vision", the x and y sensors unused: the
  /// axes step open loop (their drive planned from the step map) on velocity commands of the
  /// visual servo watching the camera's frames (perception/vision_positioner.h); z keeps its loop.
  std::string xy_sensor = "encoders";
  /// The positioner's tracker, servo and timing with `xy_sensor: vision` (docs/parameters.md).
  perception::VisionPositionerParams vision;
  motion::StepMapParams step_map;
  /// Finger-tip position (world frame) when the three axes are at 0 (mid-stroke).
  double home_x_m = -0.2e-3;
  double home_y_m = 0.0;
  double home_z_m = 0.45e-3;
  /// The rotary axis under the gripper (motion/rotary_axis.h): on by default
  /// on the simulated platform; a driver set has one when its drivers bring it.
  motion::RotaryAxisParams rotary;
  /// An axis whose target has stood still, and which has been within park_tolerance_m of it for
  /// park_after_s, is parked: its loop off, its drive held at the last voltage. Friction holds a
  /// stick-slip slider where it is (so a real controller ends its "hold time": SmarAct MCS2's
  /// hold time, PI's servo-off on target); a parked simulated axis at rest costs no integration.
  /// A target that moves resumes the loop from there. 0 s never parks. The rotary axis' tolerance
  /// is its arc (10 nm: 2 urad at 5 mm).
  double park_after_s = 0.1;
  double park_tolerance_m = 10e-9;
  bool vision_xy() const { return xy_sensor == "vision"; }

  template <class V>
  void visit(V& v) {
    v("control", control);
    v("tracking_enabled", tracking_enabled);
    v("tracking", tracking);
    v("sensor", sensor);
    v("xy_sensor", xy_sensor);
    v("vision", vision);
    v("step_map", step_map);
    v("home_x_m", home_x_m);
    v("home_y_m", home_y_m);
    v("home_z_m", home_z_m);
    v("rotary", rotary);
    v("park_after_s", park_after_s);
    v("park_tolerance_m", park_tolerance_m);
  }
  static motion::TrackingParams default_tracking() {
    motion::TrackingParams p;  // 10 kHz: updated at every loop tick (LoopParams.base_rate_Hz)
    return p;
  }
  static motion::PositionControlParams default_control() {
    motion::PositionControlParams p;
    p.control_rate_Hz = 1000.0;  // the slave rate of LoopParams
    return p;
  }
};

struct HapticMasterParams {
  haptics::DualStagePlantParams plant;
  haptics::RenderPipelineParams render;
  haptics::PantographParams pantograph;

  template <class V>
  void visit(V& v) {
    v("plant", plant);
    v("render", render);
    v("pantograph", pantograph);
  }
};

/// Which camera the platform images with (docs/hardware.md): "none", "simulated" (the image
/// formation of vision/ rendering the microworld) or a registered camera driver ("opencv": a
/// camera OpenCV's VideoCapture opens, a V4L2 device, a GStreamer pipeline or a video file).
struct CameraSelection {
  std::string driver = "simulated";  ///< "none", "simulated" or a registered camera driver
  /// What the driver opens: for "opencv" a device index ("0"), a device file, a file name or a
  /// GStreamer pipeline ending in "appsink".
  std::string source;

  template <class V>
  void visit(V& v) {
    v("driver", driver);
    v("source", source);
  }
};

/// Which devices the platform runs on (docs/hardware.md): "simulated", the digital twin, or a
/// driver set registered under that name (platform/driver_registry.h).
struct DeviceSelection {
  std::string driver = "simulated";  ///< "simulated" or a registered driver set
  /// What the driver opens, in the driver's own syntax (a device file, HOST:PORT, a bus id);
  /// unused by the simulation.
  std::string connection;
  /// On a driver set: "driver" (its own gripper) or "simulated", a simulated gripper and
  /// microworld carried by the driver's stage (hardware in the loop: the finger tips follow its
  /// sensors). Ignored by the simulation, whose gripper is always simulated.
  std::string gripper = "driver";
  CameraSelection camera;

  template <class V>
  void visit(V& v) {
    v("driver", driver);
    v("connection", connection);
    v("gripper", gripper);
    v("camera", camera);
  }
  bool simulated() const { return driver == "simulated"; }
};

/// The parallel positioner's section (`parallel_positioner:`): the simulated positioner's
/// parameters (motion::ParallelStageParams: its geometry, its legs' tracking and sensors, its
/// moves' limits, which a driver's positioner keeps for its kinematics and the moves' planning)
/// and which device is the positioner (docs/hardware.md, "pi-hexapod").
///
///     parallel_positioner: {driver: pi-hexapod, connection: "192.168.10.7:50000,timeout_s=0.2"}
struct ParallelPositionerSelection : motion::ParallelStageParams {
  /// "simulated" (the six stick-slip legs of the project's model) or a registered positioner
  /// driver ("pi-hexapod": a PI C-887 hexapod controller over TCP; platform/driver_registry.h).
  std::string driver = "simulated";
  /// What the driver opens, in its own syntax (`pi-hexapod`: HOST:PORT[,key=value...]); unused by
  /// the simulation.
  std::string connection;
  /// Where the simulated positioner's legs are stepped: "loop" (on the platform's loop, every
  /// tick: a run is reproducible; studies and tests), "thread" (on a controller thread of its
  /// own paced by the wall clock, as a real controller steps its legs on its own processor: the
  /// loop only exchanges commands and poses with it), or "auto" (the default): "thread" in a live
  /// session (`serve`, deployment::live_params), "loop" everywhere else.
  std::string controller = "auto";
  /// The controller thread's wake period, host timeout and command ring (controller: thread).
  devices::ParallelPositionerControllerParams controller_thread;

  template <class V>
  void visit(V& v) {
    motion::ParallelStageParams::visit(v);
    v("driver", driver);
    v("connection", connection);
    v("controller", controller);
    v("controller_thread", controller_thread);
  }
  bool simulated() const { return driver == "simulated"; }
  bool controller_on_thread() const { return controller == "thread"; }
};

struct PlatformConfig {
  DeviceSelection devices;
  LoopParams loop;
  teleop::TeleoperationParams teleop;
  StageParams stage;
  std::string stickslip_params_file;  ///< empty: the built-in SLC-1720-like axis
  HapticMasterParams haptic;
  tweezers::TeleTweezParams tweezers;
  /// What the slave works in: "pick-place" (the gripper over a part, `world`) or
  /// "optical-trap" (a trapped probe bead and a stuck bead, `optical_trap`; thesis §3.5.2).
  std::string microworld = "pick-place";
  microworld::PickPlaceParams world;
  microworld::OpticalTrapSceneParams optical_trap;
  /// The microscope camera and its focus drive; which camera: devices.camera.
  devices::CameraDeviceParams camera;
  /// The grip force measured by vision, live (vision_grip_force.h).
  perception::VisionGripForceParams vision_force;
  /// What positions the part: "cartesian", nothing but the XYZ stage carrying the gripper (the
  /// default), or "parallel", the thesis's assembly (§2.3, Fig. 2.4): the part on the 6-DOF
  /// parallel stick-slip positioner (`parallel_positioner`, devices/parallel_positioner.h), the
  /// gripper on the Cartesian robot.
  std::string positioner = "cartesian";
  /// The parallel positioner (with `positioner: parallel`): its model's parameters and its driver.
  ParallelPositionerSelection parallel_positioner;
  /// What the haptic master's x, y, z drive while it holds control: "stage", the Cartesian robot
  /// carrying the gripper (the default), or "positioner" (with `positioner: parallel`), the
  /// parallel positioner carrying the part, whose pose then follows the handle within its moves'
  /// limits while the console's dial turns it about the vertical (Platform, "The master on the
  /// positioner"). The gripper keeps the TéléTweez either way; the console drives the Cartesian robot.
  std::string master_drives = "stage";
  /// The PiezoGripper's tips levelled by touch on the substrate (the console's Level tips; a gripper
  /// with align drives): microworld/tip_alignment.h, Platform::start_tip_levelling.
  microworld::TipAlignmentParams alignment;

  template <class V>
  void visit(V& v) {
    v("devices", devices);
    v("loop", loop);
    v("teleop", teleop);
    v("stage", stage);
    v("stickslip_params_file", stickslip_params_file);
    v("haptic", haptic);
    v("tweezers", tweezers);
    v("microworld", microworld);
    v("world", world);
    v("optical_trap", optical_trap);
    v("camera", camera);
    v("vision_force", vision_force);
    v("positioner", positioner);
    v("parallel_positioner", parallel_positioner);
    v("master_drives", master_drives);
    v("alignment", alignment);
  }
  bool optical_trap_scene() const { return microworld == "optical-trap"; }
  bool parallel_positioner_enabled() const { return positioner == "parallel"; }
  bool master_drives_positioner() const { return master_drives == "positioner"; }
  /// Validates every section and their consistency (rates); errors name the key path.
  void validate() const;
};

/// The optical-tweezers scene (`serve --scene optical-trap`) on `config`: its microworld, and the
/// coupling's scales for a bead a hundred times smaller than a watch part: 1 cm of hand moves
/// the trap by 5 um; 1 pN of probe force is 10 mN in the hand, rendered up to 1 kHz (the
/// crossover's band, not the pick-and-place's 30 Hz smoothing: the thermal agitation is what the
/// operator should feel, Fig. 3.15); the console's speed limited to 20 um/s. The product of the
/// scales sets the stiffness the trap shows the hand, motion_scale * force_scale * k = 50 N/m:
/// above the finger's 228 N/m the loop through the finger oscillates (the probe lags its trap,
/// so every motion of the trap comes back as a force that moves the handle further). The stage
/// holds and creeps with the hybrid position controller, not the tracking controller: the
/// target then jitters by nanometres with the force in the operator's finger, which the
/// tracking controller (tuned for references moving at 50-500 um/s) amplified into 35 nm of
/// trap motion and a probe force 1.9 times the thermal one; the hybrid controller follows it
/// within 5 nm and leaves the thermal force (0.19 pN against 0.20 pN).
void use_optical_trap_scene(PlatformConfig& config);

/// Reads a configuration file over the defaults; relative file names in it are resolved
/// against the file's directory. Throws InvalidInput / InvalidParams (exit 3).
PlatformConfig load_platform_config(const std::filesystem::path& file);

/// The stick-slip parameters the configuration names (the built-in default when none).
stickslip::StickSlipParams axis_params(const PlatformConfig& config);

/// What the perception components need of the configuration: the camera, the stage's home and
/// the gripper's fingers (world.gripper).
perception::CameraRig camera_rig(const PlatformConfig& config);

}  // namespace mc::platform
