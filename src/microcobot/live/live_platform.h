#pragma once
/// @file
/// The platform run live (`microcobot serve`): its loop paced to the wall clock in
/// its real-time thread, for as long as the server runs, operated by the console.
///
///   server thread  --ConsoleCommand--> SPSC ring --> console source --+
///   protocol thread --ProtocolCommand--> ring ---> protocol source ---+--> arbiter (operator
///   DDS thread     --microscope, remote--> rings --> their sources ----+    task, 1 kHz) --> coupling
///   any thread     --estop()--> atomic flag ------> operator task: fault_all() at once
///   any thread     --request(reset|demo|restart)--> control thread, between two loop runs
///   loop           --telemetry--> ring --> drain thread --> sink (server, recording)
///
/// Every input is a CommandSource and one CommandArbiter (command_arbiter.h) gives the coupling
/// to one of them at each tick, in this order: the microscope (never drives), the remote master
/// (a slave process: then the only driver), the scripted demo, the console, the caller's
/// sources (LiveParams::sources), the vendor protocols. The console's commands are its heartbeat: when the
/// controlling client's last command is older than `command_timeout_s` (or nobody holds control) the coupling
/// sees stale commands and the stage holds (the platform's watchdog). The e-stop latches until an explicit
/// reset: devices reconfigured and re-activated off the loop (like ros2_control's lifecycle transitions,
/// which never run inside update()). "demo" and "restart" rebuild the scene (about a second: the step map)
/// with the scripted pick-and-place operator or the console in control. With a task (`serve --cell`,
/// live_task.h) the loop also runs the automatic insertion, supervised from the console. Nothing on the loop
/// path allocates, locks, throws or does I/O.

#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "microcobot/cell/pick_place_operator.h"
#include "microcobot/live/command_arbiter.h"
#include "microcobot/live/command_source.h"
#include "microcobot/live/console_command.h"
#include "microcobot/live/console_source.h"
#include "microcobot/live/demo_source.h"
#include "microcobot/live/live_looker.h"
#include "microcobot/live/live_status.h"
#include "microcobot/live/live_task.h"
#include "microcobot/live/microscope_source.h"
#include "microcobot/live/protocol_command.h"
#include "microcobot/live/protocol_source.h"
#include "microcobot/live/remote_link.h"
#include "microcobot/live/remote_source.h"
#include "microcobot/perception/vision_grip_force.h"
#include "microcobot/perception/vision_positioner.h"
#include "microcobot/platform/platform.h"
#include "microcobot/runtime/spsc_ring.h"
#include "microcobot/runtime/timing_stats.h"

namespace mc::live {

struct LiveParams {
  platform::PlatformConfig platform;  ///< loop.realtime is forced on
  cell::PickPlaceOperatorParams demo;
  double command_timeout_s = 0.2;       ///< the console's commands go stale after this long
  double placement_tolerance_m = 5e-6;  ///< shown around the target (the session's criterion)
  bool paced = true;                    ///< false: as fast as possible (tests that need no wall clock)
  /// A protocol client's axis is on target (GCS ONT?) once within this distance of its goal...
  double on_target_tolerance_m = 1e-6;
  /// ...for this long (the settle window).
  double settle_window_s = 0.02;
  /// The devices of each scene (re)build; empty: the simulated platform. A master process of a
  /// distributed platform gives the remote slave stage here (net/remote_slave.h); the scripted
  /// demo needs the simulation and is refused then.
  std::function<devices::DeviceSet()> make_devices;
  /// Commands from the far end instead of the console (a slave process: net/remote_master.h);
  /// not owned, must outlive the live platform. The console then observes (and may e-stop).
  RemoteLink* remote = nullptr;
  /// More inputs to the loop, ranked in this order below the console and above the vendor
  /// protocols (command_arbiter.h); not owned, must outlive the live platform.
  std::vector<CommandSource*> sources;
  /// The automatic insertion the console supervises (`serve --cell`; live_task.h), on the scene
  /// of `platform.world` (its job's). Not with a remote command source.
  std::optional<LiveTaskParams> task;
  /// Channels added to the telemetry of every platform built here, after the built-in ones
  /// (Platform::add_telemetry_channel): each source runs on the loop and must be real-time safe.
  struct AddedChannel {
    platform::TelemetryChannel channel;
    platform::Platform::TelemetrySource source;
  };
  std::vector<AddedChannel> telemetry_channels;
  void validate() const;
};

class LivePlatform {
 public:
  using Sink = std::function<void(const platform::TelemetrySample&, std::size_t channel_count)>;
  /// Validates and builds the platform (about a second). Throws mc::Error.
  explicit LivePlatform(LiveParams params);
  ~LivePlatform();
  LivePlatform(const LivePlatform&) = delete;
  LivePlatform& operator=(const LivePlatform&) = delete;

  /// Where the camera's frames go, with their mid-exposure time in live time (the camera thread;
  /// keep it quick: a slow sink only costs frames, never the loop). Set before start(); kept
  /// across scene rebuilds.
  using FrameSink = std::function<void(const devices::CameraFrame&, double t_live_s)>;
  void set_frame_sink(FrameSink sink);
  /// Whether anyone looks at the frames (a subscribed client, a recording); while not, the
  /// camera forms none (devices::Camera::set_wanted). Any thread; applied by the loop, kept
  /// across scene rebuilds.
  void set_camera_wanted(bool wanted) noexcept { camera_wanted_.store(wanted, std::memory_order_relaxed); }
  /// Whether anyone needs the frames as JPEG (devices::Camera::set_jpeg_wanted). Any thread;
  /// applied by the loop, kept across scene rebuilds.
  void set_camera_jpeg_wanted(bool wanted) noexcept {
    camera_jpeg_wanted_.store(wanted, std::memory_order_relaxed);
  }
  /// Whether the platform images (devices.camera.driver is not "none"), and its parameters.
  bool has_camera() const { return has_camera_; }
  const devices::CameraDeviceParams& camera_params() const { return params_.platform.camera; }

  /// Starts the control thread, which runs the loop; telemetry samples reach `sink` on the
  /// drain thread (keep it quick). Times are shifted to live time.
  void start(Sink sink);
  /// Every device to its safe state, the loop stopped, the threads joined. Idempotent.
  void stop();

  /// The controlling client's command (one producer thread: the server's). Wait-free.
  bool push_command(const ConsoleCommand& c) noexcept { return console_->push(c); }
  /// The console's pose move or stop for the parallel positioner (console_pose_goal.h; the same
  /// producer thread as push_command). Wait-free; false when the ring is full.
  bool push_console_pose_move(const ConsolePoseMove& m) noexcept { return console_->push_pose_move(m); }
  /// What the loop last published of the positioner for the console. One reader: that thread.
  ConsolePoseView console_pose_view() noexcept { return console_->pose_view(); }
  /// A microscope command from the network (net/microscope_link.h: the slave's microscope topic;
  /// one producer thread): only its focus, objective, exposure and gain count. Wait-free; false
  /// when the ring is full. Applied at the next operator tick in every role: the focus drive and
  /// the turret move the objective, no part of the slave (as the console's microscope controls).
  bool push_microscope_command(const ConsoleCommand& c) noexcept { return microscope_->push(c); }
  /// Whether a client holds control (its commands count; otherwise the stage holds).
  void set_console_in_control(bool in_control) noexcept { console_->set_in_control(in_control); }
  bool console_in_control() const noexcept { return console_->in_control(); }
  /// A vendor-protocol client's command (one producer thread: the protocol thread).
  /// Wait-free; false when the ring is full. It counts only while no console client holds control.
  bool push_protocol_command(const ProtocolCommand& c) noexcept { return protocol_->push(c); }
  /// What the loop last published for the protocol clients. Any thread.
  ProtocolView protocol_view() const noexcept;
  /// What the loop last published of the parallel positioner (`positioner: parallel`). One reader
  /// thread: the protocol thread.
  PositionerView positioner_view() noexcept { return protocol_->positioner_view(); }
  /// The operator's control of the task (one producer thread: the server's). Wait-free; false
  /// without a task or when its ring is full.
  bool push_task_action(TaskAction a) noexcept { return task_ && task_->push(a); }
  bool has_task() const noexcept { return task_ != nullptr; }
  /// Latches the e-stop at the next operator tick (at most 1 ms). Any thread, async-signal-safe.
  void estop() noexcept { estop_.store(true); }
  /// Reset, demo, restart or next part, done by the control thread between two loop runs; other
  /// actions are the server's business and ignored here. One the platform cannot do here (a demo
  /// without the simulation, a next part without a batch) is refused in the status' last_error.
  void request(ConsoleAction action);
  /// Force by vision's tare at the next frame: the operator says nothing is between the
  /// fingers. Any thread; false when the platform measures no force by vision.
  bool request_vision_tare() noexcept {
    if (!grip_gauge_) return false;
    grip_gauge_->request_tare();
    return true;
  }

  /// The gripper's tips levelled at the next tick, under the console's deadman (ConsoleSource::
  /// request_tip_levelling). Any thread; false when the gripper has no align drives.
  bool request_tip_levelling() noexcept {
    if (!readings_.has_levelling()) return false;
    console_->request_tip_levelling();
    return true;
  }

  LiveStatus status() const;
  /// Moves the command-to-target latencies measured by the loop since the last call (from the
  /// server's receipt of a command to the tick that applies it) into `stats`. One consumer
  /// thread.
  void drain_command_latencies(runtime::TimingStats& stats) noexcept { console_->drain_latencies(stats); }
  /// Moves the remote end's cost to the loop measured since the last call into `stats`: the
  /// duration of its poll() and publish() in each operator tick (the network link's whole work
  /// on the loop thread; none without a remote end). One consumer thread.
  void drain_link_costs(runtime::TimingStats& stats) noexcept {
    if (remote_) remote_->drain_costs(stats);
  }
  /// The loop's thread (tests prove it never allocates while the server runs). Started only.
  std::thread::id loop_thread_id() const { return platform_->loop().thread_id(); }
  const ConsoleLimits& limits() const { return limits_; }
  const LiveParams& params() const { return params_; }
  /// The scene's microworld: the batch part's the task works on (`serve --cell`; the parts never
  /// change, the index is atomic), else the platform's. Any thread.
  const microworld::PickPlaceParams& scene_world() const noexcept {
    if (task_ && !params_.task->parts.empty())
      return params_.task->parts[static_cast<std::size_t>(task_->part())].world;
    return params_.platform.world;
  }
  /// The scene's geometry, for the microscope view (world coordinates).
  double part_side_m() const { return scene_world().part_side_m; }
  double part_height_m() const { return scene_world().height_m(); }
  double hole_side_m() const { return scene_world().hole_side_m; }
  double part_yaw_rad() const { return scene_world().part_yaw_rad; }
  double hole_yaw_rad() const { return scene_world().hole_yaw_rad; }
  double hole_depth_m() const { return scene_world().hole_depth_m; }
  std::array<double, 3> target_m() const {
    const auto& w = scene_world();
    return {w.target_m.x(), w.target_m.y(), 0.0};
  }
  double placement_tolerance_m() const { return params_.placement_tolerance_m; }
  /// The optical-trap scene (else the pick-and-place's part, hole and target above).
  bool optical_trap_scene() const { return params_.platform.optical_trap_scene(); }
  const microworld::OpticalTrapSceneParams& optical_trap() const { return params_.platform.optical_trap; }
  /// The stuck bead's centre (world frame; optical-trap scene).
  std::array<double, 2> obstacle_m() const {
    const auto& st = params_.platform.stage;
    const Eigen::Vector2d c = params_.platform.optical_trap.obstacle_m({st.home_x_m, st.home_y_m});
    return {c.x(), c.y()};
  }
  /// The fingers' width as the camera sees them (world.gripper.finger_width_m).
  double finger_width_m() const { return scene_world().gripper.finger_width_m; }
  double finger_length_m() const { return scene_world().gripper.finger_length_m; }
  /// Why the scripted demo cannot run here (empty: it can).
  std::string demo_unavailable_reason() const;
  /// The force limits the platform enforces (teleop/safety_limits.h).
  double grip_force_limit_N() const { return scene_world().grip_force_limit_N; }
  double contact_force_limit_N() const { return scene_world().contact_force_limit_N; }
  /// The telemetry's channels (the same across scene rebuilds); a sample's first
  /// channel_count() values are these.
  const platform::TelemetrySchema& telemetry_schema() const { return telemetry_; }
  std::size_t channel_count() const { return telemetry_.size(); }

 private:
  void build(bool demo);
  /// The cell camera's looker for the task's current part (off the loop: it starts a thread).
  void make_looker();
  /// Every device simulated here (the scripted demo needs their ground truth).
  bool whole_simulation() const {
    return !params_.make_devices && !params_.remote && params_.platform.devices.simulated();
  }
  void operator_tick(const runtime::TickInfo& t) noexcept;
  void control_thread();
  void attach_camera(platform::Platform& p);
  /// The sources in the arbiter's order (the constructor).
  void add_sources();

  LiveParams params_;
  ConsoleLimits limits_;
  platform::TelemetrySchema telemetry_;  ///< set by the first build, before any thread starts
  std::unique_ptr<platform::Platform> platform_;
  std::unique_ptr<LiveTask> task_;  // kept across scene rebuilds (its ring is the server's)
  // The cell camera's looks for the task: the drain thread keeps the latest sample for them.
  std::mutex latest_mutex_;
  platform::TelemetrySample latest_sample_{};
  bool has_latest_ = false;
  std::unique_ptr<LiveLooker> looker_;  // after what it uses: destroyed (joined) first
  Eigen::Vector3d home_m_ = Eigen::Vector3d::Zero();
  std::unique_ptr<perception::VisionPositioner> positioner_;  // stage.xy_sensor: vision
  std::unique_ptr<perception::VisionGripForce> grip_gauge_;   // vision_force.enabled
  // The inputs (kept across scene rebuilds: their rings are other threads') and their arbiter.
  std::unique_ptr<MicroscopeSource> microscope_;
  std::unique_ptr<RemoteSource> remote_;  // a slave process only
  std::unique_ptr<DemoSource> demo_;
  std::unique_ptr<ConsoleSource> console_;
  std::unique_ptr<ProtocolSource> protocol_;
  CommandArbiter arbiter_;
  double t_offset_s_ = 0.0;

  std::atomic<bool> estop_{false}, interrupt_{false}, quit_{false};
  std::atomic<bool> started_{false}, camera_wanted_{true}, camera_jpeg_wanted_{true};
  std::atomic<int> loop_request_{-1};  // a ConsoleAction the loop asks of the control thread
  Sink sink_;
  FrameSink frame_sink_;
  std::atomic<bool> has_camera_{false};  // written by each build (the control thread), read by status()
  std::thread thread_;

  // Status written by the loop (atomics) and by the control thread (under status_mutex_, never
  // taken by the loop).
  LoopReadings readings_;
  std::atomic<std::uint64_t> restarts_{0}, camera_frames_{0};
  mutable std::mutex request_mutex_;  // control thread and requesters; never the loop
  int pending_ = -1;                  // a ConsoleAction, or -1
  std::string last_error_;
};

}  // namespace mc::live
