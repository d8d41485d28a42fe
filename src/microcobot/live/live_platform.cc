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

void LivePlatform::vision_tick(Platform& p, const runtime::TickInfo& t, const teleop::ConsoleInput& in,
                               bool console_drives) noexcept {
  // A jog run: long enough for a few sawtooth periods, short enough to stop with the stick.
  constexpr double kJogRun_s = 0.02;
  const bool enabled = console_drives && in.active && in.fresh && in.deadman && !p.faulted();
  positioner_->set_enabled(enabled);
  const double now = t_offset_s_ + t.t_s;
  perception::PositionerCommand c;
  while (vision_.pop(c)) {
    const double interval = c.interval_s - (now - c.t_issue_s);  // what is left of it
    if (!enabled || interval <= 0.0) continue;
    for (int i = 0; i < 2; ++i) p.command_open_loop_velocity(i, c.velocity_m_s[i], interval);
  }
  // The joystick in the plane (no goal pending): open-loop runs while it asks.
  if (!enabled || latest_.has_goal || latest_.has_goal_px) return;
  for (int i = 0; i < 2; ++i) {
    const double v = in.velocity_m_s[i];
    if (v != 0.0 && !p.open_loop_running(i)) p.command_open_loop_velocity(i, v, kJogRun_s);
  }
}

void LivePlatform::build(bool demo) {
  // A new scene: the old platform's devices are deactivated (safe state) by its destructor.
  demo_.reset();
  platform_.reset();
  if (demo && !whole_simulation())
    throw InvalidInput("demo: the scripted operator needs the whole simulated platform in this process");
  auto p = params_.make_devices ? std::make_unique<Platform>(params_.platform, params_.make_devices())
                                : platform::make_platform(params_.platform);
  std::unique_ptr<PickPlaceOperator> op;
  if (demo) op = std::make_unique<PickPlaceOperator>(*p, params_.demo);
  p->set_operator([this](const runtime::TickInfo& t) { operator_tick(t); });
  channel_count_ = p->telemetry_channel_count();
  has_camera_ = p->camera() != nullptr;
  camera_frames_.store(0);
  attach_camera(*p);
  platform_ = std::move(p);
  demo_ = std::move(op);
  demo_running_.store(demo);
  demo_finished_ = false;
  demo_error_m_.store(std::numeric_limits<double>::quiet_NaN());
  demo_duration_s_.store(0.0);
  demo_outcome_.store(static_cast<int>(demo ? DemoResult::Outcome::kRunning : DemoResult::Outcome::kNone),
                      std::memory_order_release);
  latest_ = ConsoleCommand{};
  last_command_t_ = -1e9;
  protocol_last_t_ = -1e9;
  protocol_fresh_ = protocol_has_goal_ = protocol_steps_pending_ = false;
  settled_s_ = {};
  remote_estopped_ = false;
  if (task_) task_->reset();  // a new scene, a new cycle (not started)
  if (positioner_) positioner_->reset();
  if (grip_gauge_) grip_gauge_->reset();
  perception::PositionerCommand stale;
  while (vision_.pop(stale)) {
  }
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
      // Measured before the frame is shown: the command's latency is the servo's, not the page's.
      const double now = t_s_.load(std::memory_order_relaxed);
      if (auto c = positioner_->on_frame(f, offset + f.t_mid_s, now)) vision_.push(*c);
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

bool LivePlatform::push_command(const ConsoleCommand& c) noexcept { return commands_.push(c); }

void LivePlatform::operator_tick(const runtime::TickInfo& t) noexcept {
  Platform& p = *platform_;
  if (estop_.exchange(false) && !p.faulted()) p.fault_all();
  if (p.camera() != nullptr)
    p.camera()->set_wanted(positioner_ != nullptr || camera_wanted_.load(std::memory_order_relaxed));
  if (interrupt_.load(std::memory_order_acquire)) p.stop();

  ConsoleCommand c;
  bool got = false;
  bool remote_fresh = false;
  // The remote end's work on this thread is timed (steady clock: a vDSO read, no system call).
  std::chrono::steady_clock::duration link_cost{};
  if (params_.remote) {
    // The master process drives: its e-stop latches ours, its release resets what it latched.
    const auto t0 = std::chrono::steady_clock::now();
    const RemoteRequest r = params_.remote->poll(t.t_s, latest_);
    link_cost = std::chrono::steady_clock::now() - t0;
    remote_fresh = r.fresh;
    if (r.estop && !p.faulted()) {
      p.fault_all();
      remote_estopped_ = true;
    }
    if (r.reset && remote_estopped_ && p.faulted()) {
      remote_estopped_ = false;
      loop_request_.store(static_cast<int>(ConsoleAction::kReset), std::memory_order_release);
      p.stop();
    }
  }
  {
    ConsoleCommand m;
    while (microscope_.pop(m)) apply_microscope(p, m);
  }
  while (!params_.remote && commands_.pop(c)) {
    got = true;
    apply_microscope(p, c);
    if (c.received_ns > 0) {
      // Applied in this tick: the command-to-target latency (a full ring drops the sample).
      const std::int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                   std::chrono::steady_clock::now().time_since_epoch())
                                   .count();
      latencies_.push(1e-9 * static_cast<double>(now - c.received_ns));
    }
  }
  if (got) {
    latest_ = c;
    last_command_t_ = t.t_s;
  }
  const bool fresh = params_.remote ? remote_fresh
                                    : in_control_.load(std::memory_order_relaxed) &&
                                          t.t_s - last_command_t_ <= params_.command_timeout_s;
  teleop::ConsoleInput in;
  const bool console_control = in_control_.load(std::memory_order_relaxed);
  const bool protocol = protocol_tick(t, console_control, in);
  // A protocol client drives only while no demo runs (it is not fresh then).
  if (!protocol && !demo_tick(t)) {
    in.active = true;
    in.fresh = fresh;
    in.deadman = latest_.deadman;
    in.velocity_m_s = {latest_.velocity_m_s[0], latest_.velocity_m_s[1], latest_.velocity_m_s[2]};
    in.has_goal = latest_.has_goal;
    in.goal_m = {latest_.goal_m[0], latest_.goal_m[1], latest_.goal_m[2]};
    in.goal_speed_m_s = latest_.goal_speed_m_s;
    in.has_gripper = latest_.has_gripper;
    in.gripper_opening_m = latest_.gripper_opening_m;
    in.gripper_shake = latest_.gripper_shake;
    in.has_theta_goal = latest_.has_theta_goal;
    in.theta_goal_rad = latest_.theta_goal_rad;
    in.theta_speed_rad_s = limits_.max_theta_speed_rad_s;
    in.theta_rate_rad_s = latest_.theta_rate_rad_s;
    // The task, supervised by the console in control: it drives or holds in the console's place.
    if (task_) task_->tick(p, home_m_, t.dt_s, console_control && !p.faulted(), fresh, in);
  }
  const bool console_drives = !protocol && !demo_running_.load(std::memory_order_relaxed);
  if (positioner_ && console_drives) {
    // The goal is the positioner's: the coupling's x and y loops are open.
    if (in.has_goal)
      positioner_->request_goal_world(in.goal_m.x(), in.goal_m.y());
    else if (latest_.has_goal_px)
      positioner_->request_goal_pixel(latest_.goal_px[0], latest_.goal_px[1]);
    else
      positioner_->clear_goal();
    in.has_goal = false;
  }
  p.set_console_input(in);
  if (positioner_) vision_tick(p, t, in, console_drives);
  protocol_publish(t);
  if (params_.remote) {
    const auto t0 = std::chrono::steady_clock::now();
    params_.remote->publish(p);
    link_cost += std::chrono::steady_clock::now() - t0;
    link_costs_.push(std::chrono::duration<double>(link_cost).count());  // a full ring drops it
  }

  t_s_.store(t_offset_s_ + t.t_s, std::memory_order_relaxed);
  estopped_.store(p.faulted(), std::memory_order_relaxed);
  fresh_.store(fresh, std::memory_order_relaxed);
  demo_phase_.store(demo_ ? static_cast<int>(demo_->phase()) : 0, std::memory_order_relaxed);
  demo_failed_phase_.store(demo_ ? static_cast<int>(demo_->failed_phase()) : 0, std::memory_order_relaxed);
  for (int i = 0; i < 3; ++i)
    lifecycle_[i].store(static_cast<int>(p.axis(i).state()), std::memory_order_relaxed);
  lifecycle_[3].store(static_cast<int>(p.gripper().state()), std::memory_order_relaxed);
  lifecycle_[4].store(static_cast<int>(p.haptic().state()), std::memory_order_relaxed);
  lifecycle_[5].store(static_cast<int>(p.tweezers().state()), std::memory_order_relaxed);
  rotary_lifecycle_.store(p.rotary_axis() ? static_cast<int>(p.rotary_axis()->state()) : -1,
                          std::memory_order_relaxed);
  overruns_.store(p.loop().overruns(), std::memory_order_relaxed);
  if (const devices::FocusDrive* focus = p.focus()) {
    focus_z_m_.store(focus->z_m(), std::memory_order_relaxed);
    focus_target_m_.store(focus->target_z_m(), std::memory_order_relaxed);
    objective_.store(focus->objective(), std::memory_order_relaxed);
    camera_dropped_.store(p.camera()->dropped(), std::memory_order_relaxed);
  }
  ticks_.store(p.loop().ticks(), std::memory_order_relaxed);
}

void LivePlatform::apply_microscope(Platform& p, const ConsoleCommand& c) noexcept {
  // Every command's microscope part counts (a later command without it changes nothing).
  devices::FocusDrive* focus = p.focus();
  if (focus == nullptr) return;
  if (c.has_focus) focus->command_z_m(c.focus_z_m);
  if (c.objective >= 0) focus->command_objective(c.objective);
  if (c.exposure_s > 0.0) p.camera()->set_exposure_s(c.exposure_s);
  if (c.gain > 0.0) p.camera()->set_gain(c.gain);
}

bool LivePlatform::demo_tick(const runtime::TickInfo& t) noexcept {
  if (!demo_ || demo_finished_) return false;
  demo_->act(t);  // the scripted operator drives the simulated masters' hands
  demo_duration_s_.store(t.t_s, std::memory_order_relaxed);
  const auto* gripper = platform_->simulation().gripper;
  if (gripper != nullptr)
    demo_error_m_.store(gripper->world().placement_error_m(gripper->world_state()),
                        std::memory_order_relaxed);
  if (!demo_->done() && !demo_->gave_up()) return true;
  // Finished: every axis holds where it is and the console has control again.
  platform_->hold();
  demo_finished_ = true;
  demo_running_.store(false, std::memory_order_relaxed);
  auto outcome = DemoResult::Outcome::kGaveUp;
  if (demo_->done() && gripper != nullptr) {
    const auto& w = gripper->world();
    const bool has_hole = w.params().hole_side_m > 0.0;
    if (has_hole && w.inserted(gripper->world_state()))
      outcome = DemoResult::Outcome::kInserted;
    else if (!has_hole && w.placement_error_m(gripper->world_state()) <= params_.placement_tolerance_m)
      outcome = DemoResult::Outcome::kPlaced;
    else
      outcome = DemoResult::Outcome::kMissed;
  }
  demo_outcome_.store(static_cast<int>(outcome), std::memory_order_release);
  return false;
}

std::string_view DemoResult::name(Outcome o) {
  switch (o) {
    case Outcome::kNone:
      return "none";
    case Outcome::kRunning:
      return "running";
    case Outcome::kPlaced:
      return "placed";
    case Outcome::kInserted:
      return "inserted";
    case Outcome::kMissed:
      return "missed";
    case Outcome::kGaveUp:
      return "gave_up";
  }
  return "none";
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
    const std::size_t channels = channel_count_;
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
  if (action != ConsoleAction::kReset && estopped_.load(std::memory_order_relaxed)) {
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
  estopped_.store(true);
}

void LivePlatform::drain_command_latencies(runtime::TimingStats& stats) noexcept {
  double latency_s = 0.0;
  while (latencies_.pop(latency_s)) stats.add(latency_s);
}

void LivePlatform::drain_link_costs(runtime::TimingStats& stats) noexcept {
  double cost_s = 0.0;
  while (link_costs_.pop(cost_s)) stats.add(cost_s);
}

LiveStatus LivePlatform::status() const {
  LiveStatus s;
  s.t_s = t_s_.load(std::memory_order_relaxed);
  s.estopped = estopped_.load(std::memory_order_relaxed);
  s.demo = demo_running_.load(std::memory_order_relaxed);
  if (s.demo)
    s.demo_phase = PickPlaceOperator::name(static_cast<PickPlaceOperator::Phase>(demo_phase_.load()));
  s.console_fresh = fresh_.load(std::memory_order_relaxed);
  for (std::size_t i = 0; i < 6; ++i) s.lifecycle[i] = static_cast<Lifecycle>(lifecycle_[i].load());
  const int rotary = rotary_lifecycle_.load();
  s.has_rotary = rotary >= 0;
  if (s.has_rotary) s.rotary_lifecycle = static_cast<Lifecycle>(rotary);
  s.overruns = overruns_.load(std::memory_order_relaxed);
  s.restarts = restarts_.load(std::memory_order_relaxed);
  s.ticks = ticks_.load(std::memory_order_relaxed);
  s.camera = has_camera_;
  s.camera_frames = camera_frames_.load(std::memory_order_relaxed);
  s.camera_dropped = camera_dropped_.load(std::memory_order_relaxed);
  s.focus_z_m = focus_z_m_.load(std::memory_order_relaxed);
  s.focus_target_m = focus_target_m_.load(std::memory_order_relaxed);
  s.objective = objective_.load(std::memory_order_relaxed);
  DemoResult& r = s.demo_result;
  r.outcome = static_cast<DemoResult::Outcome>(demo_outcome_.load(std::memory_order_acquire));
  r.placement_error_m = demo_error_m_.load(std::memory_order_relaxed);
  r.duration_s = demo_duration_s_.load(std::memory_order_relaxed);
  if (r.outcome != DemoResult::Outcome::kNone) {
    // The operator's phase and failed phase are the loop's; read through its atomic copy.
    r.phase = std::string(PickPlaceOperator::name(static_cast<PickPlaceOperator::Phase>(demo_phase_.load())));
    switch (r.outcome) {
      case DemoResult::Outcome::kGaveUp:
        r.reason = std::string(PickPlaceOperator::give_up_reason(
            static_cast<PickPlaceOperator::Phase>(demo_failed_phase_.load())));
        r.phase = std::string(
            PickPlaceOperator::name(static_cast<PickPlaceOperator::Phase>(demo_failed_phase_.load())));
        break;
      case DemoResult::Outcome::kPlaced:
        r.reason = "the part rests within the placement tolerance of its target";
        break;
      case DemoResult::Outcome::kInserted:
        r.reason = "the pin is down in its hole";
        break;
      case DemoResult::Outcome::kMissed:
        r.reason = scene_world().hole_side_m > 0.0 ? "the pin is not in its hole"
                                                   : "the part rests outside the placement tolerance";
        break;
      default:
        break;
    }
  }
  if (task_) s.task = task_->status();
  if (positioner_) s.vision = positioner_->status();
  if (grip_gauge_ && has_camera_) s.grip_vision = grip_gauge_->status();
  std::lock_guard lock(request_mutex_);
  s.last_error = last_error_;
  return s;
}

}  // namespace mc::live
