#include "microcobot/platform/platform.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <vector>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "microcobot/platform/driver_registry.h"
#include "microcobot/platform/simulated_device_set.h"

namespace mc::platform {
namespace {

// Room for a few seconds of telemetry between drains; the drain thread empties it every ms.
constexpr std::size_t kRingCapacity = 8192;

}  // namespace

Platform::Platform(const PlatformConfig& config)
    : config_(config),
      world_((config_.validate(),
              require(config_.devices.simulated(), "devices.driver",
                      "'" + excerpt(config_.devices.driver) +
                          "' selects hardware drivers; this runs the simulated platform only (microcobot "
                          "serve runs on drivers; in C++, make_platform)"),
              config_.world)),
      haptic_watchdog_(static_cast<std::uint32_t>(config_.loop.watchdog_ticks)),
      tweezers_watchdog_(static_cast<std::uint32_t>(config_.loop.watchdog_ticks)),
      home_m_(config_.stage.home_x_m, config_.stage.home_y_m, config_.stage.home_z_m),
      loop_(config_.loop.base_rate_Hz),
      ring_(kRingCapacity) {
  model_ = std::make_unique<stickslip::ActuatorModel>(axis_params(config_));
  SimulatedDeviceSet built = build_simulated_devices(config_, *model_, world_, home_m_);
  devices_ = std::move(built.devices);
  sim_ = built.simulation;
  build();
}

Platform::Platform(const PlatformConfig& config, devices::DeviceSet drivers)
    : config_(config),
      world_((config_.validate(), config_.world)),
      devices_(std::move(drivers)),
      haptic_watchdog_(static_cast<std::uint32_t>(config_.loop.watchdog_ticks)),
      tweezers_watchdog_(static_cast<std::uint32_t>(config_.loop.watchdog_ticks)),
      home_m_(config_.stage.home_x_m, config_.stage.home_y_m, config_.stage.home_z_m),
      loop_(config_.loop.base_rate_Hz),
      ring_(kRingCapacity) {
  if (config_.devices.gripper == "simulated") add_simulated_gripper(config_, world_, home_m_, devices_, sim_);
  // A driver set's companions may be the simulated masters (drivers/sim_companions.h): the
  // scripted operator moves their hands as on the simulated platform.
  sim_.haptic = dynamic_cast<devices::SimulatedHapticMaster*>(devices_.haptic.get());
  sim_.tweezers = dynamic_cast<devices::SimulatedTweezersMaster*>(devices_.tweezers.get());
  const char* names[10] = {"axes[0]",  "axes[1]", "axes[2]", "gripper", "haptic",
                           "tweezers", "camera",  "focus",   "rotary",  "positioner"};
  const auto d = devices();
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (i >= 6 && d[i] == nullptr) continue;  // optional: the camera, its focus, the rotary axis, ...
    if (d[i] == nullptr) throw InvalidParams(std::string("devices.") + names[i], "is missing");
    if (d[i]->state() != devices::Lifecycle::kUnconfigured)
      throw InvalidParams(std::string("devices.") + names[i], "must be handed over unconfigured");
  }
  model_ = std::make_unique<stickslip::ActuatorModel>(axis_params(config_));
  build();
}

void Platform::build() {
  const double dt = config_.loop.period_s();
  const double ratio = dt / model_->dt_s();
  require(std::abs(ratio - std::round(ratio)) < 1e-6 * ratio && ratio >= 1.0, "loop.base_rate_Hz",
          "the loop period must be a whole number of stick-slip model steps", config_.loop.base_rate_Hz);
  position_controlled_ = devices_.axes[0]->position_controlled();
  for (std::size_t i = 0; i < 4; ++i) {
    const devices::SlaveAxis* a = i < 3 ? devices_.axes[i].get() : devices_.rotary.get();
    if (a == nullptr) continue;
    require(a->position_controlled() == position_controlled_, "devices.axes",
            "must all be position-controlled or all voltage-driven", static_cast<double>(i));
    const double period = a->sample_period_s();
    require(std::abs(period - model_->dt_s()) <= 1e-9 * model_->dt_s(), "devices.axes.sample_period_s",
            "must equal the stick-slip model's step (integrator.dt_s)", period);
  }
  vision_xy_ = config_.stage.vision_xy();
  require(!(vision_xy_ && position_controlled_), "stage.xy_sensor",
          "vision needs voltage-driven axes (a position-controlled stage closes its own loop)", 1.0);
  map_ = std::make_unique<motion::StepMap>(*model_, config_.stage.step_map);
  stage_ = std::make_unique<StageController>(
      config_.stage.control, model_->params(), *map_, static_cast<int>(std::lround(ratio)), model_->dt_s(),
      config_.stage.tracking_enabled ? &config_.stage.tracking : nullptr, devices_.rotary ? 4 : 3);
  for (auto& st : steppers_)
    st = std::make_unique<devices::OpenLoopStepper>(static_cast<int>(std::lround(ratio)), model_->dt_s(),
                                                    model_->params().drive.slew_rate_V_s);
  teleop::SafetyLimitParams limits;
  limits.grip_force_limit_N = world_.params().grip_force_limit_N;
  limits.contact_force_limit_N = world_.params().contact_force_limit_N;
  limits.finger_stiffness_N_m = world_.params().gripper.finger_stiffness_N_m;
  limits.floor_m = world_.params().min_tip_height_m - home_m_.z();  // the substrate is at world z = 0
  teleop_ = std::make_unique<teleop::Teleoperation>(config_.teleop, dt, Eigen::Vector3d::Zero(),
                                                    world_.params().gripper.max_opening_m, limits);
  build_rotary();
  build_positioner();
  build_telemetry();
  if (!devices_.camera && config_.camera.enabled) {
    if (auto source = make_camera_source(config_))
      devices_.camera = std::make_unique<devices::Camera>("camera", config_.camera, std::move(source));
  }
  if (devices_.camera && !devices_.focus)
    devices_.focus = std::make_unique<devices::FocusDrive>("focus", config_.camera);

  arm_devices(/*fault_on_failure=*/false);
  if (devices_.gripper->has_align_drives())
    alignment_ =
        std::make_unique<microworld::TipAlignment>(config_.alignment, devices_.gripper->align_limit_V());

  loop_.add_task("operator", config_.loop.operator_divisor, [this](const runtime::TickInfo& t) {
    if (operator_) operator_(t);
  });
  loop_.add_task("teleoperation", 1, [this](const runtime::TickInfo&) { teleoperation_task(); });
  loop_.add_task("slave_control", config_.loop.slave_divisor,
                 [this](const runtime::TickInfo&) { slave_control_task(); });
  loop_.add_task("devices", 1, [this](const runtime::TickInfo& t) { devices_task(t.dt_s); });
  loop_.add_task("telemetry", config_.loop.telemetry_divisor,
                 [this](const runtime::TickInfo&) { telemetry_task(); });
  if (devices_.camera) loop_.add_task("camera", 1, [this](const runtime::TickInfo& t) { camera_task(t); });
  loop_.sample_ticks_every(config_.loop.telemetry_divisor);
  loop_.pin_to_core(config_.loop.cpu);
}

Platform::~Platform() {
  for (devices::Device* d : devices())
    if (d != nullptr) d->deactivate();
}

std::array<devices::Device*, 10> Platform::devices() {
  return {devices_.axes[0].get(), devices_.axes[1].get(),   devices_.axes[2].get(), devices_.gripper.get(),
          devices_.haptic.get(),  devices_.tweezers.get(),  devices_.camera.get(),  devices_.focus.get(),
          devices_.rotary.get(),  devices_.positioner.get()};
}

const devices::SimulatedDevices& Platform::simulation() const {
  if (sim_.haptic == nullptr && sim_.gripper == nullptr)
    throw InvalidParams("platform", "runs on hardware drivers, not on the simulation");
  return sim_;
}

void Platform::fault_all() noexcept {
  for (devices::Device* d : devices())
    if (d != nullptr) d->fault();
  stage_->emergency_stop();
  for (auto& st : steppers_) st->halt();
  faulted_ = true;
  if (tip_levelling_running()) end_levelling(TipLevellingStatus::State::kFailed, "a fault or the e-stop");
}

void Platform::teleoperation_task() noexcept {
  // The watchdogs see whether each master produced a reading since the last tick.
  if (devices_.haptic->reading_count() != haptic_seen_) haptic_watchdog_.feed();
  if (devices_.tweezers->reading_count() != tweezers_seen_) tweezers_watchdog_.feed();
  haptic_seen_ = devices_.haptic->reading_count();
  tweezers_seen_ = devices_.tweezers->reading_count();

  teleop::TeleoperationInput in;
  const devices::Vec2 h = devices_.haptic->handle_position_m();
  in.handle_m = {h.x, h.y};
  in.deadman = devices_.haptic->enabled() && !faulted_;
  in.clutch = devices_.haptic->clutch();
  in.z_jog_m_s = devices_.haptic->jog_m_s();
  in.haptic_fresh = haptic_watchdog_.tick();
  in.tweezers_opening_m = devices_.tweezers->opening_m();
  in.tweezers_fresh = tweezers_watchdog_.tick();
  // The master on the parallel positioner moves the part: the coupling's slave is the positioner's
  // plate, and the contact it renders is the fingers' reaction on the part.
  const bool to_positioner = master_on_positioner();
  if (to_positioner != coupling_.master_on) switch_master_slave(to_positioner);
  for (int i = 0; i < 3; ++i)
    in.slave_position_m[i] = devices_.axes[static_cast<std::size_t>(i)]->position_m();
  const devices::Vec3 f = devices_.gripper->contact_force_N();
  in.contact_force_N = {f.x, f.y, f.z};
  if (to_positioner) {
    in.slave_position_m = devices_.positioner->measured_pose().d;
    in.contact_force_N = -in.contact_force_N;
  }
  teleop_->set_height_ceiling(to_positioner ? plate_ceiling_m(devices_.positioner->measured_pose().R)
                                            : std::numeric_limits<double>::infinity());
  // The tips' floor over a seat the positioner raised: the Cartesian robot's target keeps above it.
  teleop_->set_height_floor(devices_.positioner && !to_positioner ? stage_floor_m()
                                                                  : -std::numeric_limits<double>::infinity());
  in.grip_force_N = devices_.gripper->grip_force_N();
  in.gripper_opening_m = devices_.gripper->opening_m();
  in.slave_fresh = to_positioner
                       ? devices_.positioner->state() == devices::Lifecycle::kActive
                       : devices_.axes[0]->measurement_fresh() && devices_.axes[1]->measurement_fresh() &&
                             devices_.axes[2]->measurement_fresh();
  in.console = console_;
  in.console.deadman = console_.deadman && !faulted_;
  const auto& out = teleop_->tick(in);
  rotary_command();
  levelling_task(config_.loop.period_s());

  devices_.haptic->command_force_N({out.haptic_force_N.x(), out.haptic_force_N.y()});
  devices_.tweezers->command_grip_force_N(out.finger_force_N);
  devices_.gripper->command_opening_m(out.gripper_opening_m);
  devices_.gripper->command_shake(out.gripper_shake);
}

void Platform::slave_control_task() noexcept {
  if (faulted_) return;
  const auto& out = teleop_->output();
  const std::array<double, 3> measured = {devices_.axes[0]->position_m(), devices_.axes[1]->position_m(),
                                          devices_.axes[2]->position_m()};
  // Operator-to-slave tracking error: the target the operator commands now against
  // where the slave is, while the coupling is engaged.
  if (out.engaged && !coupling_.master_on) {
    const double e = (out.slave_target_m - Eigen::Vector3d(measured[0], measured[1], measured[2])).norm();
    tracking_.sum_sq_m2 += e * e;
    tracking_.max_m = std::max(tracking_.max_m, e);
    ++tracking_.samples;
  }
  std::array<double, StageController::kMaxAxes> target{}, velocity{}, all_measured{};
  for (std::size_t i = 0; i < 3; ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    target[i] = out.slave_target_m[k], velocity[i] = out.slave_velocity_m_s[k], all_measured[i] = measured[i];
  }
  if (coupling_.master_on) {  // the master moves the part: the gripper holds where it was
    for (std::size_t i = 0; i < 3; ++i)
      target[i] = coupling_.stage_hold_m[static_cast<Eigen::Index>(i)], velocity[i] = 0.0;
  }
  rotary_control(target, velocity, all_measured);
  levelling_targets(target, velocity);
  if (position_controlled_) {
    // The stage's own loop (the slave process) follows the target.
    for (std::size_t i = 0; i < 3; ++i) devices_.axes[i]->command_target_m(target[i], velocity[i]);
    if (devices_.rotary) devices_.rotary->command_target_m(target[3], velocity[3]);
    return;
  }
  // An axis stepping open loop is not the controller's: it idles there (target = measured), so
  // that it takes over bumplessly when the run ends.
  for (std::size_t i = 0; i < steppers_.size(); ++i) {
    if (steppers_[i]->running()) {
      target[i] = all_measured[i];  // the rotary axis' too (measured holds x, y, z only)
      velocity[i] = 0.0;
    }
  }
  park_still_axes(target, all_measured);
  stage_->update(target, velocity, all_measured);
}

void Platform::devices_task(double dt_s) noexcept {
  bool stepping_ended = false;
  for (std::size_t i = 0; i < 3; ++i) {
    devices::OpenLoopStepper& st = *steppers_[i];
    const bool was_running = st.running();
    if (was_running && open_loop_must_stop(i)) st.halt();
    if (!faulted_ && !position_controlled_) {
      if (vision_xy_ && i < 2) {
        devices_.axes[i]->command_drive(st.drive());  // its run, or 0 V at rest: no loop on x, y
      } else if (st.running()) {
        const devices::DriveBlock open_loop = st.drive();
        stage_->drive(static_cast<int>(i), devices_.axes[i]->position_m());  // keeps the controller's clock
        devices_.axes[i]->command_drive(open_loop);
      } else {
        devices_.axes[i]->command_drive(stage_->drive(static_cast<int>(i), devices_.axes[i]->position_m()));
      }
    }
    devices_.axes[i]->update(dt_s);
    stepping_ended |= was_running && !st.running();
  }
  stepping_ended |= rotary_drive(dt_s);
  // Every automatic move ends holding: the targets re-taken where the axes are.
  if (stepping_ended) hold_axes();
  positioner_task(dt_s);
  devices_.gripper->update(dt_s);
  devices_.haptic->update(dt_s);
  devices_.tweezers->update(dt_s);
  if (devices_.camera) {
    devices_.camera->update(dt_s);
    devices_.focus->update(dt_s);
  }
  if (!faulted_) {
    for (devices::Device* d : devices()) {
      if (d != nullptr && d->state() == devices::Lifecycle::kFault) {
        fault_all();
        break;
      }
    }
  }
}

void Platform::camera_task(const runtime::TickInfo& t) noexcept {
  // The tool's and the part's positions over the last ticks give their mean velocities (the
  // motion blur of the exposure); the camera sees the true scene, not the sensors' readings.
  Eigen::Vector3d tool, part = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < 3; ++i) {
    tool[static_cast<Eigen::Index>(i)] =
        home_m_[static_cast<Eigen::Index>(i)] + devices_.axes[i]->carried_position_m();
  }
  if (sim_.gripper != nullptr) part = sim_.gripper->part_position_m();
  if (sim_.optical_tweezers != nullptr) part = sim_.optical_tweezers->bead_m();
  const std::size_t oldest = history_index_;  // the entry written kVelocityTicks ticks ago
  const Eigen::Vector3d tool_then = tool_history_[oldest], part_then = part_history_[oldest];
  tool_history_[history_index_] = tool;
  part_history_[history_index_] = part;
  history_index_ = (history_index_ + 1) % kVelocityTicks;
  if (!devices_.camera->frame_due(t.t_s) || !devices_.camera->wanted()) return;

  devices::SceneSnapshot s;
  s.t_s = t.t_s;
  s.steady_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                    std::chrono::steady_clock::now().time_since_epoch())
                    .count();
  const bool history = loop_.ticks() > kVelocityTicks;
  const double span_s = static_cast<double>(kVelocityTicks) * t.dt_s;
  for (int i = 0; i < 3; ++i) {
    s.tool_m[i] = tool[i];
    s.tool_velocity_m_s[i] = history ? (tool[i] - tool_then[i]) / span_s : 0.0;
  }
  s.gripper_opening_m = devices_.gripper->opening_m();
  s.tool_yaw_rad = sim_.gripper != nullptr ? sim_.gripper->yaw_rad() : yaw_rad();
  s.gripper_free_opening_m = devices_.gripper->free_opening_m();
  if (sim_.gripper != nullptr) {
    s.has_part = true;
    s.part_phase = static_cast<int>(sim_.gripper->world_state().phase);
    s.part_yaw_rad = sim_.gripper->part_yaw_rad();
    const devices::CarriedSeat& seat = sim_.gripper->seat();
    s.seat_m[0] = seat.T.d.x(), s.seat_m[1] = seat.T.d.y();
    s.seat_yaw_rad = seat.yaw_rad();
    const Eigen::Vector2d bend = sim_.gripper->finger_deflection_m();
    s.finger_deflection_m[0] = bend.x(), s.finger_deflection_m[1] = bend.y();
  }
  if (sim_.optical_tweezers != nullptr) {
    s.has_beads = true;
    const Eigen::Vector2d obstacle = sim_.optical_tweezers->obstacle_m();
    s.obstacle_bead_m[0] = obstacle.x();
    s.obstacle_bead_m[1] = obstacle.y();
  }
  for (int i = 0; i < 3; ++i) {
    (s.has_beads ? s.probe_bead_m : s.part_m)[i] = part[i];
    s.part_velocity_m_s[i] = history ? (part[i] - part_then[i]) / span_s : 0.0;
  }
  s.focus_z_m = devices_.focus->z_m();
  s.objective = devices_.focus->objective();
  s.exposure_s = devices_.camera->exposure_s();
  s.gain = devices_.camera->gain();
  devices_.camera->publish(s);  // a full ring drops the frame (counted); the loop goes on
}

void Platform::drain() noexcept {
  TelemetrySample s;
  while (ring_.pop(s)) recorder_->sample(std::span<const double>(s.data(), telemetry_channel_count()));
}

void Platform::set_console_input(const teleop::ConsoleInput& in) noexcept {
  console_ = in;
  // World coordinates (the telemetry's) to the coupling's, which are relative to home.
  console_.goal_m = in.goal_m - home_m_;
}

void Platform::set_fixtures(const teleop::FixtureSet& set) noexcept {
  teleop::FixtureSet stage = set;
  stage.guide_xy_m = set.guide_xy_m - home_m_.head<2>();
  stage.path_from_xy_m = set.path_from_xy_m - home_m_.head<2>();
  stage.rim_z_m = set.rim_z_m - home_m_.z();
  stage.height_z_m = set.height_z_m - home_m_.z();
  for (auto& k : stage.keep_outs) {
    k.xy_m -= home_m_.head<2>();
    k.top_z_m -= home_m_.z();
  }
  teleop_->set_fixtures(stage);
  const auto& fp = config_.teleop.fixtures;
  if (rotary_target_)
    rotary_target_->set_stop(set.yaw, set.yaw_rad, set.level, fp.yaw_capture_rad, fp.level_rate_1_s);
}

void Platform::hold() noexcept {
  hold_axes();
  stop_pose_move();
}

void Platform::hold_axes() noexcept {
  const Eigen::Vector3d measured(devices_.axes[0]->position_m(), devices_.axes[1]->position_m(),
                                 devices_.axes[2]->position_m());
  if (coupling_.master_on) {  // the coupling drives the positioner: its target is the plate's
    coupling_.stage_hold_m = measured;
    teleop_->hold_at(devices_.positioner->measured_pose().d);
  } else {
    teleop_->hold_at(measured);
  }
  if (rotary_target_) rotary_target_->hold_at(yaw_rad());
}

void Platform::arm_devices(bool fault_on_failure) {
  // Configure, then activate; a device that throws leaves none of them armed.
  try {
    for (devices::Device* d : devices())
      if (d != nullptr) d->configure();
    for (devices::Device* d : devices())
      if (d != nullptr) d->activate();
  } catch (...) {
    for (devices::Device* d : devices())
      if (d != nullptr) fault_on_failure ? d->fault() : d->deactivate();
    throw;
  }
}

void Platform::recover() {
  arm_devices(/*fault_on_failure=*/true);  // a refused reset stays latched
  faulted_ = false;
}

void Platform::run_streaming(double duration_s, const TelemetrySink& sink) {
  require(duration_s > 0.0, "duration_s", "must be > 0", duration_s);
  run_loop(duration_s, [this, &sink] {
    TelemetrySample s;
    while (ring_.pop(s)) sink(s);
  });
}

void Platform::run_loop(double duration_s, const std::function<void()>& drain_fn) {
  const double max_ticks = 9e18;
  const double want = duration_s * config_.loop.base_rate_Hz;
  const auto ticks = static_cast<std::uint64_t>(std::llround(std::min(want, max_ticks)));
  // The drain runs beside the loop: telemetry leaves the loop only through the ring.
  std::atomic<bool> done{false};
  std::thread drainer([&] {
    while (!done.load(std::memory_order_acquire)) {
      drain_fn();
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  if (config_.loop.realtime) {
    loop_.run_realtime(ticks);
  } else {
    loop_.run_for(ticks);
  }
  done.store(true, std::memory_order_release);
  drainer.join();
  drain_fn();
}

void Platform::run(double duration_s) {
  require(std::isfinite(duration_s) && duration_s > 0.0, "duration_s", "must be > 0", duration_s);
  const auto ticks = static_cast<std::uint64_t>(std::llround(duration_s * config_.loop.base_rate_Hz));
  // Room for the whole run's telemetry, allocated before the loop starts.
  const std::size_t need =
      recorder_->size() + ticks / static_cast<std::uint64_t>(config_.loop.telemetry_divisor) + 2;
  if (need > recorder_->capacity()) {
    // Grown geometrically: a caller stepping the platform by short runs (the cell's cycles, one
    // second at a time) would otherwise copy the whole recording at every run.
    auto bigger = std::make_unique<Recorder>(telemetry_.names(), std::max(need, 2 * recorder_->capacity()));
    TelemetrySample s;
    for (std::size_t i = 0; i < recorder_->size(); ++i) {
      for (std::size_t c = 0; c < telemetry_channel_count(); ++c) s[c] = recorder_->at(i, c);
      bigger->sample(std::span<const double>(s.data(), telemetry_channel_count()));
    }
    recorder_ = std::move(bigger);
  }
  run_loop(duration_s, [this] { drain(); });
}

}  // namespace mc::platform
