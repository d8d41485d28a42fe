#include "microcobot/live/live_platform.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "microcobot/core/error.h"
#include "microcobot/platform/driver_registry.h"

namespace mc::live {

using cell::PickPlaceOperator;
using devices::Lifecycle;
using platform::Platform;

void LiveParams::validate() const {
  platform.validate();
  demo.validate();
  require(std::isfinite(command_timeout_s) && command_timeout_s >= 0.01 && command_timeout_s <= 10.0,
          "command_timeout_s", "must be within [0.01, 10] s", command_timeout_s);
  require(placement_tolerance_m > 0 && placement_tolerance_m < 1e-3, "placement_tolerance_m",
          "must be within (0, 1 mm)", placement_tolerance_m);
  require(std::isfinite(on_target_tolerance_m) && on_target_tolerance_m > 0 && on_target_tolerance_m < 1e-3,
          "on_target_tolerance_m", "must be within (0, 1 mm)", on_target_tolerance_m);
  require(std::isfinite(settle_window_s) && settle_window_s >= 0 && settle_window_s <= 10.0,
          "settle_window_s", "must be within [0, 10] s", settle_window_s);
  if (platform.stage.vision_xy()) {
    require(!task, "platform.stage.xy_sensor",
            "vision positions the console's click-to-go; the supervised task needs encoders", 1.0);
    require(remote == nullptr, "platform.stage.xy_sensor",
            "vision runs where the camera is: the master process, not a slave", 1.0);
  }
  if (task) {
    require(remote == nullptr, "task",
            "the console supervises a task only where it drives (not a slave process)");
    task->validate();
    require(!task->camera.enabled || (!make_devices && platform.devices.simulated()), "task.camera.enabled",
            "the cell's camera renders the simulation: every device simulated");
  }
}

LivePlatform::LivePlatform(LiveParams params) : params_(std::move(params)) {
  params_.platform.loop.realtime = params_.paced;
  params_.validate();
  home_m_ = {params_.platform.stage.home_x_m, params_.platform.stage.home_y_m,
             params_.platform.stage.home_z_m};
  if (params_.task) {
    task_ = std::make_unique<LiveTask>(*params_.task);
    if (!params_.task->parts.empty()) params_.platform.world = scene_world();
  }
  make_looker();
  if (params_.platform.stage.vision_xy())
    positioner_ = std::make_unique<perception::VisionPositioner>(platform::camera_rig(params_.platform),
                                                                 params_.platform.stage.vision);
  // Force by vision wherever a camera looks at the gripper (not the optical trap's beads).
  const platform::PlatformConfig& pc = params_.platform;
  if (pc.vision_force.enabled && !pc.optical_trap_scene())
    grip_gauge_ = std::make_unique<perception::VisionGripForce>(platform::camera_rig(pc), pc.vision_force);
  add_sources();
  build(/*demo=*/false);
  const auto& tp = params_.platform.teleop;
  limits_.max_speed_m_s = tp.console_max_speed_m_s;
  const double home[3] = {params_.platform.stage.home_x_m, params_.platform.stage.home_y_m,
                          params_.platform.stage.home_z_m};
  for (std::size_t i = 0; i < 3; ++i) {
    limits_.min_m[i] = home[i] + tp.workspace_min_m;
    limits_.max_m[i] = home[i] + tp.workspace_max_m;
  }
  limits_.max_opening_m = params_.platform.world.gripper.max_opening_m;
  limits_.has_positioner = platform_->has_positioner();
  limits_.pose_max_speed_m_s = params_.platform.parallel_positioner.move.max_speed_m_s;
  limits_.pose_max_angular_speed_rad_s = params_.platform.parallel_positioner.move.max_angular_speed_rad_s;
  if (platform_->has_rotary()) {
    limits_.min_theta_rad = platform_->yaw_min_rad();
    limits_.max_theta_rad = platform_->yaw_max_rad();
    limits_.max_theta_speed_rad_s = params_.platform.stage.rotary.max_speed_rad_s;
  }
  const devices::CameraDeviceParams& cam = params_.platform.camera;
  limits_.focus_min_m = cam.focus_min_m;
  limits_.focus_max_m = cam.focus_max_m;
  limits_.objective_count = has_camera_ ? static_cast<int>(cam.objectives.size()) : 0;
  limits_.max_exposure_s = 1.0 / cam.frame_rate_Hz();
  if (has_camera_) limits_.max_goal_px = {cam.sensor.width_px - 1.0, cam.sensor.height_px - 1.0};
}

LivePlatform::~LivePlatform() { stop(); }

void LivePlatform::add_sources() {
  const platform::PlatformConfig& pc = params_.platform;
  const double theta_speed = pc.stage.rotary.max_speed_rad_s;
  microscope_ = std::make_unique<MicroscopeSource>();
  demo_ = std::make_unique<DemoSource>(params_.placement_tolerance_m);
  ConsoleSourceParams cp;
  cp.home_m = home_m_;
  cp.command_timeout_s = params_.command_timeout_s;
  cp.max_theta_speed_rad_s = theta_speed;
  console_ = std::make_unique<ConsoleSource>(cp, task_.get(), positioner_.get());
  ProtocolSourceParams pp;
  pp.home_m = home_m_;
  pp.command_timeout_s = params_.command_timeout_s;
  pp.on_target_tolerance_m = params_.on_target_tolerance_m;
  pp.settle_window_s = params_.settle_window_s;
  pp.rotary_radius_m = pc.stage.rotary.radius_m;
  protocol_ = std::make_unique<ProtocolSource>(pp);
  // The order is the rank (command_arbiter.h): a console user in control outranks automation,
  // the demo outranks the console, the far master of a slave process is the only driver.
  arbiter_.add(*microscope_);
  if (params_.remote) {
    remote_ = std::make_unique<RemoteSource>(*params_.remote, theta_speed);
    arbiter_.add(*remote_);
  } else {
    arbiter_.add(*demo_);
    arbiter_.add(*console_);
  }
  for (CommandSource* source : params_.sources) arbiter_.add(*source);
  arbiter_.add(*protocol_);
}

void LivePlatform::build(bool demo) {
  // A new scene: the old platform's devices are deactivated (safe state) by its destructor.
  demo_->start(nullptr);
  platform_.reset();
  if (demo && !whole_simulation())
    throw InvalidInput("demo: the scripted operator needs the whole simulated platform in this process");
  auto p = params_.make_devices ? std::make_unique<Platform>(params_.platform, params_.make_devices())
                                : platform::make_platform(params_.platform);
  std::unique_ptr<PickPlaceOperator> op;
  if (demo) op = std::make_unique<PickPlaceOperator>(*p, params_.demo);
  p->set_operator([this](const runtime::TickInfo& t) { operator_tick(t); });
  for (const auto& added : params_.telemetry_channels) p->add_telemetry_channel(added.channel, added.source);
  // A rebuild keeps the devices and the added channels: the same telemetry (read by the server's
  // threads without a lock, so written only by the first build).
  if (telemetry_.empty()) {
    telemetry_ = p->telemetry_schema();
  } else if (p->telemetry_schema() != telemetry_) {
    throw InvalidInput("live platform: a rebuilt scene changed the telemetry's channels");
  }
  has_camera_ = p->camera() != nullptr;
  camera_frames_.store(0);
  attach_camera(*p);
  platform_ = std::move(p);
  demo_->start(std::move(op));
  arbiter_.reset();  // nobody holds control in a new scene; every source forgets
  console_->set_time_offset(t_offset_s_);
  if (task_) task_->reset();  // a new scene, a new cycle (not started)
  if (positioner_) positioner_->reset();
  if (grip_gauge_) grip_gauge_->reset();
}

void LivePlatform::make_looker() {
  looker_.reset();  // joined before its successor starts
  if (!task_ || !params_.task->camera.enabled) return;
  looker_ = std::make_unique<LiveLooker>(params_.task->camera, params_.platform, task_->params(), *task_,
                                         [this](platform::TelemetrySample& out) {
                                           std::lock_guard lock(latest_mutex_);
                                           out = latest_sample_;
                                           return has_latest_;
                                         });
}

void LivePlatform::set_frame_sink(FrameSink sink) {
  if (started_.load()) throw InvalidInput("live platform: set the frame sink before start()");
  frame_sink_ = std::move(sink);
  attach_camera(*platform_);
}

void LivePlatform::attach_camera(Platform& p) {
  // Without a sink the camera forms no frame (camera_device.h); vision positioning needs them.
  if (p.camera() == nullptr || (!frame_sink_ && !positioner_ && !grip_gauge_)) return;
  p.camera()->set_sink([this, offset = t_offset_s_](const devices::CameraFrame& f) {
    camera_frames_.fetch_add(1, std::memory_order_relaxed);  // for the status
    perception::VisionGripForce::ToolHint hint;
    if (positioner_) {
      // Before the frame is shown: the command's latency is the servo's, not the page's.
      const auto now = [this] { return readings_.t_s(); };
      if (auto c = positioner_->on_frame(f, offset + f.t_mid_s, now)) console_->push_vision(*c);
      // Without x, y sensors the tips are looked for where the positioner sees the tool.
      const perception::PositionerStatus st = positioner_->status();
      hint.stage_sensed = false;
      if (st.found) hint.pixel = Eigen::Vector2d(st.tool_u_px, st.tool_v_px);
    }
    // Before the frame is shown: its camera state carries the force seen in it.
    if (grip_gauge_) grip_gauge_->on_frame(f, hint);
    if (frame_sink_) frame_sink_(f, offset + f.t_mid_s);
  });
}

void LivePlatform::operator_tick(const runtime::TickInfo& t) noexcept {
  Platform& p = *platform_;
  if (estop_.exchange(false) && !p.faulted()) p.fault_all();
  if (p.camera() != nullptr) {
    // The JPEG demand first: a camera woken by this tick forms its first frame with it.
    p.camera()->set_jpeg_wanted(camera_jpeg_wanted_.load(std::memory_order_relaxed));
    p.camera()->set_wanted(positioner_ != nullptr || camera_wanted_.load(std::memory_order_relaxed));
  }
  if (interrupt_.load(std::memory_order_acquire)) p.stop();

  const SourceTick source_tick{t, p};
  teleop::ConsoleInput in;
  if (arbiter_.tick(source_tick, in).reset) {
    // A source releases the e-stop it latched: the reset, by the control thread.
    loop_request_.store(static_cast<int>(ConsoleAction::kReset), std::memory_order_release);
    p.stop();
  }
  p.set_console_input(in);
  arbiter_.publish(source_tick);

  readings_.publish(p, t_offset_s_ + t.t_s);
}

std::string LivePlatform::demo_unavailable_reason() const {
  if (!whole_simulation())
    return "demo: the scripted operator needs the whole simulated platform in this process";
  if (params_.platform.optical_trap_scene())
    return "demo: the scripted operator is the pick-and-place; the optical-trap scene is operated by hand";
  if (positioner_)
    return "demo: the scripted operator needs the stage's encoders (stage.xy_sensor is vision: use "
           "click-to-go)";
  return "";
}

void LivePlatform::start(Sink sink) {
  if (started_.exchange(true)) throw InvalidInput("live platform: already started");
  sink_ = std::move(sink);
  thread_ = std::thread([this] { control_thread(); });
}

void LivePlatform::control_thread() {
  const double forever = std::numeric_limits<double>::infinity();
  while (!quit_.load()) {
    const double offset = t_offset_s_;
    const std::size_t channels = telemetry_.size();
    platform_->run_streaming(forever, [this, offset, channels](const platform::TelemetrySample& s) {
      platform::TelemetrySample shifted = s;
      shifted[0] += offset;
      sink_(shifted, channels);
      if (looker_) {  // the drain thread, not the loop: a lock is fine here
        std::lock_guard lock(latest_mutex_);
        latest_sample_ = s;
        has_latest_ = true;
      }
    });
    if (quit_.load()) break;
    int action = -1;
    {
      std::lock_guard lock(request_mutex_);
      action = pending_;
      pending_ = -1;
      const int from_loop = loop_request_.exchange(-1, std::memory_order_acq_rel);
      if (action < 0) action = from_loop;
      interrupt_.store(false, std::memory_order_release);
    }
    try {
      if (action == static_cast<int>(ConsoleAction::kReset)) {
        platform_->recover();
      } else if (action == static_cast<int>(ConsoleAction::kDemo) ||
                 action == static_cast<int>(ConsoleAction::kRestart)) {
        t_offset_s_ += platform_->loop().time_s();
        build(action == static_cast<int>(ConsoleAction::kDemo));
        restarts_.fetch_add(1);
      } else if (action == static_cast<int>(ConsoleAction::kNextPart)) {
        // The batch's next part: its world for the platform, its goal for the task, the looker's
        // scene; the readers of the scene go through scene_world() (the part's index).
        const int n = static_cast<int>(params_.task->parts.size());
        t_offset_s_ += platform_->loop().time_s();
        task_->set_part((task_->part() + 1) % n);
        params_.platform.world = scene_world();
        make_looker();
        build(false);
        restarts_.fetch_add(1);
      }
    } catch (const std::exception& e) {
      std::lock_guard lock(request_mutex_);
      last_error_ = e.what();
      if (platform_ && !platform_->faulted()) platform_->fault_all();
    }
  }
}

void LivePlatform::request(ConsoleAction action) {
  if (action != ConsoleAction::kReset && action != ConsoleAction::kDemo &&
      action != ConsoleAction::kRestart && action != ConsoleAction::kNextPart)
    return;
  std::lock_guard lock(request_mutex_);
  // A new scene would bring the devices up again: while the e-stop (or a fault) holds them in
  // their safe state, only an explicit reset releases them.
  if (action != ConsoleAction::kReset && readings_.estopped()) {
    last_error_ = std::string(action == ConsoleAction::kDemo       ? "demo"
                              : action == ConsoleAction::kNextPart ? "next_part"
                                                                   : "restart") +
                  ": the e-stop holds every device in its safe state; reset first";
    return;
  }
  if (action == ConsoleAction::kNextPart && (!task_ || params_.task->parts.empty())) {
    last_error_ = "next_part: there is no batch here (serve --cell serves one)";
    return;
  }
  if (action == ConsoleAction::kDemo) {
    if (std::string why = demo_unavailable_reason(); !why.empty()) {
      last_error_ = std::move(why);
      return;
    }
  }
  pending_ = static_cast<int>(action);
  last_error_.clear();
  interrupt_.store(true, std::memory_order_release);
}

void LivePlatform::stop() {
  if (!started_.load() || !thread_.joinable()) return;
  quit_.store(true);
  interrupt_.store(true, std::memory_order_release);
  thread_.join();
  // Safe state now; the devices are deactivated when the platform goes.
  platform_->fault_all();
  // No frame reaches the sink after stop() (its owner may go first): set_sink waits for one
  // being delivered.
  if (platform_->camera() != nullptr) platform_->camera()->set_sink(nullptr);
  readings_.set_stopped();
}

ProtocolView LivePlatform::protocol_view() const noexcept {
  ProtocolView v = protocol_->view();
  v.console_in_control = console_->in_control();
  v.halted = readings_.estopped();
  return v;
}

LiveStatus LivePlatform::status() const {
  LiveStatus s;
  readings_.fill(s);
  s.demo = demo_->running();
  s.demo_phase = demo_->phase_name();
  s.console_fresh = remote_ ? remote_->fresh() : console_->fresh();
  s.control = std::string(arbiter_.holder_name());
  s.restarts = restarts_.load(std::memory_order_relaxed);
  s.camera = has_camera_;
  s.camera_frames = camera_frames_.load(std::memory_order_relaxed);
  s.demo_result = demo_->result(scene_world().hole_side_m > 0.0);
  if (task_) s.task = task_->status();
  if (positioner_) s.vision = positioner_->status();
  if (grip_gauge_ && has_camera_) s.grip_vision = grip_gauge_->status();
  std::lock_guard lock(request_mutex_);
  s.last_error = last_error_;
  return s;
}

}  // namespace mc::live
