#pragma once
/// @file
/// The cobotic platform of Fig. 1.12-1.13 assembled from its configuration: the masters (the
/// dual-stage haptic interface and the TéléTweez), the slave (three stick-slip axes carrying
/// the micro-gripper in its microworld), the teleoperation coupling between them, the slave
/// stage's controller, and the fixed-rate loop that runs it all:
///
///   every tick (10 kHz)      watchdogs, teleoperation, force commands to the masters;
///                            drive samples to the axes; every device's update()
///   every slave tick (1 kHz) the stage controller on the measured positions and the targets
///   every operator tick      the (scripted) operator acts, if one is attached
///   every telemetry tick     one sample into a single-producer ring, drained off the loop
///   every frame (camera rate) the scene's snapshot into the camera's ring (camera_device.h)
///
/// The devices are reached through their interfaces only (device.h): the default platform
/// builds the simulated ones, another constructor takes hardware drivers (docs/hardware.md).
///
/// With `positioner: parallel` (the thesis's assembly, §2.3, Fig. 2.4) the part rides on the 6-DOF
/// parallel positioner, one more device updated on every tick (platform_positioner.cc); its pose
/// moves run only under the deadman of the input that drives the coupling.
///
/// A device that faults (a diverged model, a driver error) puts every device in its safe
/// state at once: the axes to 0 V, the forces to zero, the gripper holding. Nothing on the
/// loop path allocates, locks, throws or does I/O (tests/platform/platform_test.cc).

#include <array>
#include <atomic>
#include <cmath>
#include <functional>
#include <memory>
#include <span>
#include <thread>
#include <vector>

#include "microcobot/core/recorder.h"
#include "microcobot/devices/camera_device.h"
#include "microcobot/devices/device_set.h"
#include "microcobot/devices/encoderless_stage.h"
#include "microcobot/devices/open_loop_stepper.h"
#include "microcobot/devices/simulated_gripper.h"
#include "microcobot/devices/simulated_haptic_master.h"
#include "microcobot/devices/simulated_optical_tweezers.h"
#include "microcobot/devices/simulated_slave_axis.h"
#include "microcobot/devices/simulated_tweezers_master.h"
#include "microcobot/microworld/pick_place_world.h"
#include "microcobot/microworld/tip_alignment.h"
#include "microcobot/motion/rotary_axis.h"
#include "microcobot/motion/step_map.h"
#include "microcobot/platform/platform_config.h"
#include "microcobot/platform/stage_controller.h"
#include "microcobot/platform/telemetry_schema.h"
#include "microcobot/runtime/fixed_rate_loop.h"
#include "microcobot/runtime/spsc_ring.h"
#include "microcobot/runtime/watchdog.h"
#include "microcobot/stickslip/actuator.h"
#include "microcobot/teleop/rotary_target.h"
#include "microcobot/teleop/teleoperation.h"

namespace mc::platform {

/// The PiezoGripper's tip levelling run on the slave (Platform::start_tip_levelling), as the loop
/// last left it.
struct TipLevellingStatus {
  enum class State : std::uint8_t { kIdle, kRunning, kDone, kFailed };
  State state = State::kIdle;
  microworld::AlignmentPhase phase = microworld::AlignmentPhase::kIdle;
  const char* failure = "";  ///< why it failed or was refused (a static string; empty otherwise)
  int passes = 0;
  double peak_contact_N = 0.0;  ///< the highest tip contact force read while it ran
  /// The tips' misalignment (finger 1's height minus finger 0's) when it started and now (the
  /// simulated gripper's truth; NaN on a driver's gripper, which does not know it).
  double misalignment_before_m = std::nan("");
  double misalignment_m = std::nan("");
};
const char* to_string(TipLevellingStatus::State s) noexcept;

class Platform {
 public:
  /// The simulated platform: builds the models (the stick-slip step map is computed here: about
  /// a second), the simulated devices and the loop, then configures and activates every device.
  /// Throws mc::Error.
  explicit Platform(const PlatformConfig& config);
  /// The platform on the given devices (hardware drivers): the stage controller still uses the
  /// stick-slip model of `config` (identified for these axes: stickslip_params_file). Every
  /// device must be present and unconfigured; they are configured and activated here (a driver
  /// that throws leaves the platform unbuilt, every device deactivated). Throws mc::Error.
  Platform(const PlatformConfig& config, devices::DeviceSet drivers);
  ~Platform();
  Platform(const Platform&) = delete;
  Platform& operator=(const Platform&) = delete;

  /// The operator's action, called at the operator rate at the start of a tick (the
  /// scripted operator of a scenario). Set before running; must be real-time safe.
  void set_operator(std::function<void(const runtime::TickInfo&)> op) { operator_ = std::move(op); }

  /// Runs for `duration_s` (as fast as possible, or paced when loop.realtime), recording the
  /// telemetry. May be called again to continue. Stops early when stop() is called.
  void run(double duration_s);
  /// Runs like run() but hands every telemetry sample to `sink` (on a thread beside the loop,
  /// about every millisecond) instead of recording it: the live server's way, whose
  /// runs have no end known in advance. `duration_s` may be infinite.
  using TelemetrySink = std::function<void(const TelemetrySample&)>;
  void run_streaming(double duration_s, const TelemetrySink& sink);

  /// The operator console's command for the next ticks, in world coordinates (the
  /// telemetry's): set from the operator task, on the loop. Real-time safe.
  void set_console_input(const teleop::ConsoleInput& in) noexcept;
  /// The console input in force (the last set_console_input()'s; its goal relative to the stage's
  /// home, as the coupling takes it).
  const teleop::ConsoleInput& console_input() const noexcept { return console_; }
  /// Shared control: the virtual fixtures on the coupling for the next ticks, in world
  /// coordinates (teleop/virtual_fixtures.h). On the loop (the operator task); real-time safe.
  void set_fixtures(const teleop::FixtureSet& set) noexcept;
  /// The haptic master's motion scale in force (the configured one times the fixtures' gain).
  double motion_scale() const noexcept { return teleop_->motion_scale(); }
  /// The fixtures in force (stage coordinates: world minus the stage's home).
  const teleop::VirtualFixtures& fixtures() const noexcept { return teleop_->fixtures(); }
  /// The motion scale the fixtures would give with the tool at `world_xy`.
  double motion_scale_at(const Eigen::Vector2d& world_xy) const noexcept {
    return teleop_->motion_scale_at(world_xy - home_m_.head<2>());
  }
  /// After an e-stop (fault_all), the explicit reset: every device configured and activated
  /// again, the stage holding where it is. Off the loop only (it may allocate): call it between
  /// runs. Throws mc::Error when a device refuses (every device is then left in its safe state).
  void recover();
  void stop() noexcept { loop_.request_stop(); }
  /// Every axis holds where it is measured (target = position, zero velocity), the coupling
  /// disengaged until the next engagement, the parallel positioner's legs too: how an automatic
  /// sequence hands control back. On the loop (the operator task); real-time safe.
  void hold() noexcept;
  /// The parallel positioner carrying the part (`positioner: parallel`), or null.
  bool has_positioner() const noexcept { return devices_.positioner != nullptr; }
  const devices::ParallelPositioner* positioner() const noexcept { return devices_.positioner.get(); }
  /// Whether a pose move may run now: not faulted, and the console input that drives the
  /// coupling active, fresh and with its deadman held (the rule of the open-loop runs).
  bool pose_move_allowed() const noexcept {
    return !faulted_ && console_.active && console_.fresh && console_.deadman;
  }
  /// The haptic master drives the parallel positioner now (`master_drives: positioner` while the
  /// console does not hold control): its handle moves the part, the Cartesian robot holds.
  bool master_on_positioner() const noexcept {
    return config_.master_drives_positioner() && devices_.positioner != nullptr && !console_.active;
  }
  /// Starts a pose move of the parallel positioner: `checked`, a trajectory motion::check_move()
  /// passed off the loop, from the pose the legs hold. False, and nothing moves, without the
  /// positioner, when pose_move_allowed() is false, while another move runs, when it starts
  /// elsewhere (devices::ParallelPositioner::start_move), or when it would bring the seat within
  /// world.min_tip_height_m of the finger tips (devices::lowest_tip_height_m). The move holds where it is as
  /// soon as pose_move_allowed() turns false (Platform::devices_task). On the loop; real-time safe.
  bool start_pose_move(const motion::PoseTrajectory& checked) noexcept;
  /// Makes the parallel positioner follow `target` (devices::ParallelPositioner::follow: the
  /// console's jog, a master's position): false, and nothing moves, without the positioner, when
  /// pose_move_allowed() is false or the positioner refuses. It holds where it is as soon as
  /// pose_move_allowed() turns false, as a move does. On the loop; real-time safe.
  bool follow_pose(const motion::PlatformTransform& target, const motion::PoseMoveLimits& limits) noexcept;
  /// The moves and followed poses of the parallel positioner the platform has stopped short of
  /// their goal (its rules: the deadman, a stale input, the seat onto the finger tips), counted
  /// from the start: how an input learns that its move ended early. Real-time safe.
  std::uint64_t pose_moves_stopped() const noexcept { return coupling_.stops; }
  /// The seat's pose on the positioner's plate as measured (identity: flat on it, the default):
  /// the floor and the refusals of the moves take the seat there (devices::CarriedSeat::on_plate).
  /// Set by whoever measured it (the cell's touch probe, cell/seat_levelling.h). Real-time safe.
  void set_seat_on_plate(const motion::PlatformTransform& mount) noexcept { coupling_.seat_on_plate = mount; }
  const motion::PlatformTransform& seat_on_plate() const noexcept { return coupling_.seat_on_plate; }
  /// Where the finger tips stand (world frame: the stage's home plus its measured axes), and the
  /// least height over the substrate any input may bring them to (world.min_tip_height_m).
  Eigen::Vector3d tips_m() const noexcept;
  double tip_floor_m() const noexcept { return world_.params().min_tip_height_m; }
  /// Ends the positioner's move: every leg holds where it is measured. Real-time safe.
  void stop_pose_move() noexcept {
    if (devices_.positioner) devices_.positioner->stop();
  }
  /// Open-loop stepping (the ANC300's `stepu`/`stepd`): `periods` sawtooth periods
  /// of `amplitude_V` at `frequency_Hz` played straight to axis `axis` (0..2; 3: the rotary
  /// axis, turning its rotor by the arc the actuator steps), forward
  /// (`direction` +1) or backward (-1), the stage controller set aside on that axis; the coupling's
  /// target follows nothing meanwhile and the axis holds where it ends (hold()). On the loop
  /// (the operator task); real-time safe. Refused (false, nothing moves) when faulted, on
  /// position-controlled axes, or with an axis, amplitude (0..drive.max_V], frequency
  /// (0, 10 kHz] or period count (1..1e9) out of range. Safety: the run stops at once (0 V, every
  /// axis holding) as soon as the console input that drives the coupling is no longer active,
  /// fresh and with its deadman held, on a fault, on a contact force over the limit, or when the
  /// axis leaves the workspace (or, on Z, goes below the floor; the rotary axis: its target's
  /// travel, yaw_min_rad()..yaw_max_rad()) in its direction of travel.
  bool start_open_loop_steps(int axis, double amplitude_V, double frequency_Hz, int direction,
                             std::int64_t periods) noexcept;
  /// Open-loop velocity (`stage.xy_sensor: vision`): axis `axis` moves by
  /// v x `interval_s` within `interval_s`, its run planned from the step map
  /// (plan_open_loop_run(): a calibration of the drive, not a sensor), then holds at rest. A
  /// displacement under half the finest step stops the axis' run instead. The rules of
  /// start_open_loop_steps() apply (deadman, faults, force, workspace). Real-time safe.
  bool command_open_loop_velocity(int axis, double velocity_m_s, double interval_s) noexcept;
  /// True when x and y are positioned by vision (`stage.xy_sensor: vision`): their stage loop is
  /// open, they move only by open-loop runs and rest at 0 V between them.
  bool vision_xy() const noexcept { return vision_xy_; }
  /// Stops every open-loop run at once (0 V) and holds every axis. Real-time safe.
  void stop_open_loop() noexcept;
  bool open_loop_running(int axis) const noexcept {
    return steppers_[static_cast<std::size_t>(axis)] && steppers_[static_cast<std::size_t>(axis)]->running();
  }
  /// Levels the PiezoGripper's tips by touch (microworld/tip_alignment.h, `alignment`): the Z
  /// axis brings the gripper down onto the substrate and the higher tip's align drive lowers it
  /// until both touch, then lifts; x and y hold where they are. An automatic sequence under the
  /// pose moves' rule: refused (false, the status says why) without a gripper with align drives,
  /// while one runs or an open-loop run does, or unless pose_move_allowed(); it stops with every
  /// axis holding (hold()) and the align drives where they are as soon as pose_move_allowed()
  /// turns false (the deadman released, the input stale or outranked, a fault, the e-stop), on a
  /// contact force over contact_force_limit_N, or a tip's over alignment.max_contact_N, and
  /// when it is done or fails. On the loop; real-time safe.
  bool start_tip_levelling() noexcept;
  /// Ends a levelling under way (failed: stopped), every axis holding. Real-time safe.
  void stop_tip_levelling() noexcept;
  /// A levelling asked for by an input that does not drive the coupling: refused, the status
  /// saying `why` (a static string); one under way goes on. Real-time safe.
  void refuse_tip_levelling(const char* why) noexcept;
  bool tip_levelling_running() const noexcept {
    return levelling_.state == TipLevellingStatus::State::kRunning;
  }
  const TipLevellingStatus& tip_levelling() const noexcept { return levelling_; }
  /// The tips' misalignment now: the simulated gripper's truth (NaN on a driver's gripper).
  double tip_misalignment_m() const noexcept;
  /// The rotary axis: present, its measured angle and its target [rad] (the
  /// console's theta commands move the target, with the console's deadman; hold() holds it).
  bool has_rotary() const noexcept { return devices_.rotary != nullptr; }
  /// Axis i (3: the rotary axis) parked on its target: its loop off, its voltage held
  /// (stage.park_after_s).
  bool parked(int i) const noexcept { return i < stage_->axis_count() && stage_->parked(i); }
  double yaw_rad() const noexcept;
  double yaw_target_rad() const noexcept;
  /// The target's travel (the axis' end stops less a margin) [rad]; 0, 0 without the axis.
  double yaw_min_rad() const noexcept { return rotary_target_ ? rotary_target_->min_rad() : 0.0; }
  double yaw_max_rad() const noexcept { return rotary_target_ ? rotary_target_->max_rad() : 0.0; }
  const devices::SlaveAxis* rotary_axis() const noexcept { return devices_.rotary.get(); }
  /// The force and floor limits the coupling enforces (teleop/safety_limits.h).
  const teleop::SafetyLimits& safety_limits() const { return teleop_->limits(); }

  /// Every device to its safe state and Fault (a fault injection or an operator's e-stop).
  void fault_all() noexcept;
  bool faulted() const noexcept { return faulted_; }

  const PlatformConfig& config() const { return config_; }
  runtime::FixedRateLoop& loop() { return loop_; }
  const runtime::FixedRateLoop& loop() const { return loop_; }
  devices::HapticMaster& haptic() { return *devices_.haptic; }
  devices::TweezersMaster& tweezers() { return *devices_.tweezers; }
  const devices::SlaveAxis& axis(int i) const { return *devices_.axes[static_cast<std::size_t>(i)]; }
  const devices::Gripper& gripper() const { return *devices_.gripper; }
  /// The camera and its focus drive; null when the platform has none.
  devices::Camera* camera() { return devices_.camera.get(); }
  devices::FocusDrive* focus() { return devices_.focus.get(); }
  const devices::FocusDrive* focus() const { return devices_.focus.get(); }
  /// True when the platform runs its simulated devices (the whole digital twin).
  bool simulated() const { return sim_.axes[0] != nullptr; }
  /// The simulated devices, null where the platform runs a driver's (on a driver set: the
  /// simulated masters of drivers/sim_companions.h, the gripper of `devices.gripper: simulated`).
  /// Throws mc::InvalidParams when none is simulated.
  const devices::SimulatedDevices& simulation() const;
  /// The simulated gripper in its microworld, or null (a driver's gripper, the optical trap).
  const devices::SimulatedGripper* simulated_gripper() const { return sim_.gripper; }
  const StageController& stage_controller() const { return *stage_; }
  /// Operator-to-slave tracking error: |slave target - measured slave position| (3-D) at every
  /// slave tick while the teleoperation coupling is engaged.
  struct TrackingErrorStats {
    double sum_sq_m2 = 0.0, max_m = 0.0;
    std::uint64_t samples = 0;
    double rms_m() const { return samples > 0 ? std::sqrt(sum_sq_m2 / static_cast<double>(samples)) : 0.0; }
  };
  const TrackingErrorStats& tracking_error() const { return tracking_; }
  const teleop::TeleoperationOutput& teleop() const { return teleop_->output(); }
  const Recorder& recording() const { return *recorder_; }
  /// True when the telemetry carries the simulation's channels (the operator's hand, the finger
  /// tips, the part): a simulated haptic master and a simulated microworld (the whole twin, or a
  /// driver set under `devices.gripper: simulated`, whose tips follow the stage's sensors).
  bool records_simulation() const {
    return sim_.haptic != nullptr && (sim_.gripper != nullptr || sim_.optical_tweezers != nullptr);
  }
  /// The channels of this platform's telemetry: the built-in loop channels, the simulation's
  /// when records_simulation(), then those added (telemetry_schema.h).
  const TelemetrySchema& telemetry_schema() const { return telemetry_; }
  std::size_t telemetry_channel_count() const { return telemetry_.size(); }
  /// Reads one added channel's value off the platform, on the loop at every telemetry tick:
  /// must be real-time safe (no allocation, lock, exception or I/O).
  using TelemetrySource = std::function<double(const Platform&)>;
  /// Adds a channel to the telemetry (after the built-in ones): it is sampled with the others
  /// and reaches every output (the recording's CSV and MCAP, the live server's schema, Python)
  /// with its name and unit. Before the first run only. Returns its index in a sample. Throws
  /// mc::InvalidParams for a channel the schema refuses (TelemetrySchema::add), without a
  /// source, or after the platform ran.
  std::size_t add_telemetry_channel(TelemetryChannel channel, TelemetrySource source);
  /// Telemetry samples lost because the ring was full (0 when the drain keeps up).
  std::size_t telemetry_dropped() const { return ring_.dropped() + recorder_->dropped(); }

  /// One tick of the loop's tasks without timing (tests, benchmarks).
  void tick_for_test() { loop_.run_for(1); }

 private:
  void teleoperation_task() noexcept;
  void slave_control_task() noexcept;
  void devices_task(double dt_s) noexcept;
  /// Whether axis i's open-loop run must stop now (the safety rules of start_open_loop_steps).
  bool open_loop_must_stop(std::size_t i) const noexcept;
  /// The tip levelling's part of each task (platform_levelling.cc): one step of the procedure at
  /// every tick, and its Z target in place of the coupling's.
  void levelling_task(double dt_s) noexcept;
  void levelling_targets(std::array<double, StageController::kMaxAxes>& target,
                         std::array<double, StageController::kMaxAxes>& velocity) const noexcept;
  void end_levelling(TipLevellingStatus::State state, const char* why) noexcept;
  void telemetry_task() noexcept;
  /// The built-in channels, each with the function that reads it (platform_telemetry.cc).
  struct BuiltinChannel;
  static std::span<const BuiltinChannel> loop_channels();
  static std::span<const BuiltinChannel> simulation_channels();
  friend const TelemetrySchema& builtin_telemetry(bool simulation);
  void build_telemetry();
  /// Axis i's drive voltage as the telemetry reports it (0 when faulted).
  double axis_voltage_V(std::size_t i) const noexcept;
  /// The simulated part's (or probe bead's) position, zero without a simulated microworld.
  Eigen::Vector3d simulated_part_m() const noexcept;
  void camera_task(const runtime::TickInfo& t) noexcept;
  void drain() noexcept;
  void run_loop(double duration_s, const std::function<void()>& drain_fn);
  void build();
  void arm_devices(bool fault_on_failure);
  /// Every device; the camera, focus drive, rotary axis and parallel positioner last, null when
  /// absent.
  std::array<devices::Device*, 10> devices();
  /// hold() without the parallel positioner: an XYZ run that ends leaves a pose move running.
  void hold_axes() noexcept;
  /// The parallel positioner's part of each task (platform_positioner.cc).
  void build_positioner();
  void positioner_task(double dt_s) noexcept;
  /// The master's and the dial's pose for the positioner (master_on_positioner()): true when one
  /// of them drives it this tick, under its deadman.
  bool master_pose_task() noexcept;
  /// The coupling's slave switched between the Cartesian robot and the positioner: each holds,
  /// and the coupling re-takes its target from the one it now drives.
  void switch_master_slave(bool to_positioner) noexcept;
  /// The highest the positioner's plate may stand turned by `R`: the seat's point under the finger
  /// tips min_tip_height_m below them.
  double plate_ceiling_m(const Eigen::Matrix3d& R) const noexcept;
  /// The lowest the Cartesian robot's z target may go (stage coordinates): the tips
  /// min_tip_height_m over the carried seat's surface under them.
  double stage_floor_m() const noexcept;
  /// The seat carried onto the finger tips since the last tick: its point under them moved up
  /// while they are under their floor over it, or along their contact force while it is over its
  /// limit (the poses a real platform knows; platform_positioner.cc).
  bool seat_closes_on_tips() noexcept;
  static std::span<const BuiltinChannel> positioner_channels();
  static std::span<const BuiltinChannel> positioner_truth_channels();
  /// The rotary axis' part of each task (platform_rotary.cc).
  void build_rotary();
  void rotary_command() noexcept;
  void rotary_control(std::array<double, StageController::kMaxAxes>& target,
                      std::array<double, StageController::kMaxAxes>& velocity,
                      std::array<double, StageController::kMaxAxes>& measured) noexcept;
  /// The rotary axis' drive for one tick; true when an open-loop run on it ended in this tick.
  bool rotary_drive(double dt_s) noexcept;
  /// Parks the axes that have arrived on still targets, resumes those whose target moved.
  void park_still_axes(const std::array<double, StageController::kMaxAxes>& target,
                       const std::array<double, StageController::kMaxAxes>& measured) noexcept;

  PlatformConfig config_;
  std::unique_ptr<stickslip::ActuatorModel> model_;
  std::unique_ptr<motion::StepMap> map_;
  microworld::PickPlaceWorld world_;
  devices::DeviceSet devices_;
  devices::SimulatedDevices sim_;  ///< all null unless simulated
  std::unique_ptr<StageController> stage_;
  std::array<std::unique_ptr<devices::OpenLoopStepper>, 4> steppers_;  ///< X, Y, Z, the rotary axis
  TrackingErrorStats tracking_;
  std::unique_ptr<teleop::Teleoperation> teleop_;
  std::unique_ptr<teleop::RotaryTarget> rotary_target_;  ///< null without the rotary axis
  /// Parking (stage.park_after_s): slave ticks each axis has stood on its still target, and the
  /// targets of the last slave tick (the rotary axis' as its arc).
  std::array<int, StageController::kMaxAxes> still_ticks_{};
  std::array<double, StageController::kMaxAxes> last_target_m_{};
  runtime::Watchdog haptic_watchdog_;
  runtime::Watchdog tweezers_watchdog_;
  std::uint64_t haptic_seen_ = 0, tweezers_seen_ = 0;
  Eigen::Vector3d home_m_;
  runtime::FixedRateLoop loop_;
  runtime::SpscRing<TelemetrySample> ring_;
  TelemetrySchema telemetry_;
  std::vector<TelemetrySource> telemetry_sources_;  ///< one per channel of telemetry_
  std::unique_ptr<Recorder> recorder_;
  std::function<void(const runtime::TickInfo&)> operator_;
  teleop::ConsoleInput console_;
  /// The tip levelling: the procedure (null without align drives), its status, and the stage
  /// target it runs (stage coordinates: x, y held, z moved at the procedure's speed).
  std::unique_ptr<microworld::TipAlignment> alignment_;
  TipLevellingStatus levelling_;
  Eigen::Vector3d levelling_target_m_ = Eigen::Vector3d::Zero();
  double levelling_velocity_m_s_ = 0.0;
  double levelling_press_N_ = 0.0, levelling_press_rate_N_s_ = 0.0;  ///< the higher tip contact, its rise
  /// The press's rise smoothed over this; the stage's stopping time the guard looks ahead by
  /// (a few slave ticks: the stick-slip axis ends the step under way).
  static constexpr double kLevellingRateTau_s = 1e-3;
  static constexpr double kLevellingStop_s = 2e-3;
  bool faulted_ = false;
  /// The parallel positioner's coupling (platform_positioner.cc): its reference at the last tick
  /// (which way the seat went), and the master on it: whether it drives it now and drove it the last
  /// tick, the pose it asks for, where the Cartesian robot holds meanwhile.
  struct PositionerCoupling {
    motion::PlatformTransform seat_reference;
    motion::PlatformTransform seat_on_plate;  ///< set_seat_on_plate()
    bool master_on = false, master_driving = false;
    motion::PlatformTransform master_pose;
    Eigen::Vector3d stage_hold_m = Eigen::Vector3d::Zero();
    std::uint64_t stops = 0;  ///< pose_moves_stopped()
  } coupling_;
  bool vision_xy_ = false;            ///< x and y open loop, positioned by vision (stage.xy_sensor)
  bool position_controlled_ = false;  ///< the axes take targets (a remote slave stage)
  /// The camera's scene (loop thread): tool and part positions of the last ticks, for velocities
  /// over the last kVelocityTicks ticks.
  static constexpr std::size_t kVelocityTicks = 10;
  std::array<Eigen::Vector3d, kVelocityTicks> tool_history_{}, part_history_{};
  std::size_t history_index_ = 0;
};

}  // namespace mc::platform
