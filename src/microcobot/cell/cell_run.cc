#include "microcobot/cell/cell_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>

#include "microcobot/cell/task_io.h"
#include "microcobot/core/error.h"
#include "microcobot/devices/simulated_gripper.h"
#include "microcobot/motion/pose_trajectory.h"

namespace mc::cell {

std::vector<std::string> cell_modes() { return {"auto", "manual", "assisted", "scripted"}; }

void CellRunParams::validate() const {
  const auto modes = cell_modes();
  if (std::find(modes.begin(), modes.end(), mode) == modes.end()) {
    std::string names;
    for (const auto& m : modes) names += (names.empty() ? "" : ", ") + m;
    throw InvalidParams("mode", "must be one of " + names + " (got '" + mode + "')");
  }
  require(std::isfinite(max_cycle_s) && max_cycle_s >= 1.0 && max_cycle_s <= 3600.0, "max_cycle_s",
          "must be within [1, 3600] s", max_cycle_s);
  task.validate();
  person.validate();
  require(person_seed >= 0, "person_seed", "must be non-negative", person_seed);
  require(std::isfinite(confirm_delay_s) && confirm_delay_s >= 0.0 && confirm_delay_s <= 60.0,
          "confirm_delay_s", "must be within [0, 60] s", confirm_delay_s);
  for (std::size_t i = 0; i < autonomy.size(); ++i) {
    const std::string key = "steps." + std::string(AssemblyTask::name(static_cast<AssemblyTask::Step>(i)));
    require(mode != "auto" || autonomy[i] != AssemblyTask::Autonomy::kAssisted, key,
            "is assisted: a headless run has no person under shared control for one step (serve --cell "
            "runs it with one)");
    require(mode != "auto" || autonomy[i] != AssemblyTask::Autonomy::kManual || person.master == "console",
            key,
            "is manual: the simulated person takes a step over with the console (person.master: console; "
            "the TéléTweez' levers would command the held pin's grip from their own opening, a click "
            "master has no gripper of its own)");
  }
  manual.validate();
  camera.validate();
  level_seat.validate();
  level_tips.validate();
  require(person.master != "click" || mode != "assisted", "person.master",
          "click: the console's click-to-go is for manual runs (the click is the platform's move already)");
  require(!camera.enabled || mode == "auto", "camera.enabled", "is the robot's (mode auto)");
}

/// What the cycle measures at every operator tick (on the loop: arithmetic only).
struct CellCycle::Meter {
  double grip_limit_N = 0.0, contact_limit_N = 0.0;
  double peak_grip = 0.0, grip_sum = 0.0, peak_contact = 0.0, path = 0.0;
  long gripped_ticks = 0;
  int grip_over = 0, contact_over = 0;
  std::array<double, AssemblyTask::kStepCount - 1> step_s{};
  void time_step(AssemblyTask::Step s, double dt_s) {
    const auto i = static_cast<std::size_t>(s);
    if (i < step_s.size()) step_s[i] += dt_s;
  }
  Eigen::Vector3d last_tip = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());

  void sample(const TaskSensors& s) {
    const double contact = s.contact_N.norm();
    peak_grip = std::max(peak_grip, s.grip_N);
    peak_contact = std::max(peak_contact, contact);
    if (s.grip_N > 0.0) {
      grip_sum += s.grip_N;
      ++gripped_ticks;
    }
    // Over the limit by more than rounding: the limits clamp the command at the limit itself.
    if (s.grip_N > grip_limit_N * (1.0 + 1e-6)) ++grip_over;
    if (contact > contact_limit_N * (1.0 + 1e-6)) ++contact_over;
    if (last_tip.allFinite()) path += (s.tip_m - last_tip).norm();
    last_tip = s.tip_m;
  }
};

namespace {

// Flat parts are placed by the robot and the simulated person (the scripted watchmaker only opens).
void require_mode_places(const AssemblyJob& job, const std::string& mode) {
  require(!job.flat || mode != "scripted", "flat_fraction",
          "gives flat parts, which the scripted watchmaker does not place (it only opens the fingers; "
          "modes auto, manual, assisted do)");
}

platform::PlatformConfig with_world(platform::PlatformConfig c, const AssemblyJob& job) {
  c.microworld = "pick-place";
  c.world = job.world;
  c.validate();
  return c;
}

}  // namespace

CellCycle::CellCycle(const AssemblyJob& job, const CellRunParams& params, platform::PlatformConfig base)
    : job_(job),
      params_(params),
      start_(std::chrono::steady_clock::now()),
      meter_(std::make_unique<Meter>()),
      vision_rng_(static_cast<std::uint64_t>(params.person_seed) * 1000003ULL +
                  static_cast<std::uint64_t>(job.index) + 0x766973696f6eULL) {
  params_.validate();
  require_mode_places(job, params_.mode);
  base = with_world(std::move(base), job);
  platform_ = std::make_unique<platform::Platform>(base);
  home_m_ = {base.stage.home_x_m, base.stage.home_y_m, base.stage.home_z_m};
  meter_->grip_limit_N = job.world.grip_force_limit_N;
  meter_->contact_limit_N = job.world.contact_force_limit_N;
  platform::Platform& p = *platform_;
  AssemblyGoal goal = assembly_goal(job);
  if (p.has_rotary()) {
    goal.yaw_min_rad = p.yaw_min_rad();
    goal.yaw_max_rad = p.yaw_max_rad();
  }
  if (params_.mode == "auto") {
    task_ = std::make_unique<AssemblyTask>(params_.task, goal);
    const bool manual_steps = std::find(params_.autonomy.begin(), params_.autonomy.end(),
                                        AssemblyTask::Autonomy::kManual) != params_.autonomy.end();
    if (manual_steps)  // the person who takes them over: the manual mode's, same seed
      person_ =
          std::make_unique<PersonOperator>(p, params_.person, params_.task, goal, false,
                                           static_cast<std::uint64_t>(params_.person_seed) * 1000003ULL +
                                               static_cast<std::uint64_t>(job.index));
    if (params_.camera.enabled) {
      camera_ = std::make_unique<CellCamera>(params_.camera, base, static_cast<std::uint64_t>(job.index));
      task_->set_looks(true, params_.camera.servo);
    }
    for (std::size_t i = 0; i + 1 < params_.autonomy.size(); ++i)
      task_->set_autonomy(static_cast<AssemblyTask::Step>(i), params_.autonomy[i]);
    const std::string& level = params_.level_seat.mode;
    require(level != "on" || p.has_positioner(), "level_seat.mode",
            "is on, but the seat does not ride on a parallel positioner (positioner: parallel)");
    if (level == "on" || (level == "auto" && p.has_positioner()))
      level_.procedure = std::make_unique<SeatLevelling>(params_.level_seat, goal.target_m,
                                                         AssemblyTask::grasp_height_m(params_.task, goal));
    if (params_.level_tips.mode == "on") {
      require(p.gripper().has_align_drives(), "level_tips.mode",
              "is on, but the gripper has no align drives");
      level_.tips = std::make_unique<TipLevellingStep>(params_.level_tips, goal.open_m);
    }
    p.set_operator([this](const runtime::TickInfo& t) {
      TaskSensors s = read_task_sensors(*platform_, home_m_);
      if (!finished_) meter_->sample(s);  // the cycle's measures end with it
      if (level_.failed) {  // a levelling failed: the cycle ended there, holding (deadman let go)
        teleop::ConsoleInput holding;
        holding.active = holding.fresh = true;
        platform_->set_console_input(holding);
        if (observer_) observer_(t.t_s);
        return;
      }
      if (level_.tips && !level_.tips->finished()) {  // before the task's first step
        level_.tips_s += t.dt_s;
        level_.tips->tick(*platform_, s);
        if (level_.tips->phase() == TipLevellingStep::Phase::kFailed) {
          level_.failed = finished_ = held_ = true;  // the step ended holding
          finished_at_s_ = t.t_s;
        }
        if (observer_) observer_(t.t_s);
        return;
      }
      if (levelling_now()) {
        meter_->time_step(task_->step(), t.dt_s);
        level_tick(s, t);
        if (observer_) observer_(t.t_s);
        return;
      }
      if (task_->step() == AssemblyTask::Step::kVerify && !camera_) {
        // The cell's camera on the pin, at the precision the assisted person's guidance has.
        const double sd = params_.person.assist_vision_sd_m;
        s.part_m = platform_->simulation().gripper->part_position_m();
        for (int i = 0; i < 3; ++i) s.part_m[i] += vision_rng_.normal(0.0, sd);
      }
      // The supervisor confirms a waiting step after confirm_delay_s (the task holds meanwhile).
      if (task_->status() == AssemblyTask::Status::kAwaitingConfirm) {
        waiting_s_ += t.dt_s;
        if (waiting_s_ >= params_.confirm_delay_s - 1e-9) {
          task_->confirm();
          ++confirmations_;
        }
      } else {
        waiting_s_ = 0.0;
      }
      // Holding (deadman off) whenever the task does not drive: paused, awaiting, finished.
      // Taken over, the operator's master drives: the console lets go.
      meter_->time_step(task_->step(), t.dt_s);
      teleop::ConsoleInput in = task_->tick(s, t.dt_s);
      if (task_->operator_drives()) in.active = false;
      platform_->set_console_input(in);
      if (person_) hand_over(t);
      // A look wanted: the loop stops at the end of this tick, the camera looks between runs.
      if (camera_ && !look_requested_ && task_->look_wanted() != AssemblyTask::Look::kNone) {
        look_requested_ = true;
        platform_->stop();
      }
      if (task_->finished() && !finished_) {
        finished_ = true;
        finished_at_s_ = t.t_s;
        platform_->hold();  // the sequence ends with every axis holding
        held_ = true;
      }
      if (observer_) observer_(t.t_s);
    });
  } else if (params_.mode == "manual" || params_.mode == "assisted") {
    const std::uint64_t seed =
        static_cast<std::uint64_t>(params_.person_seed) * 1000003ULL + static_cast<std::uint64_t>(job.index);
    person_ = std::make_unique<PersonOperator>(p, params_.person, params_.task, goal,
                                               params_.mode == "assisted", seed);
    p.set_operator([this](const runtime::TickInfo& t) {
      if (!finished_) meter_->sample(read_task_sensors(*platform_, home_m_));
      meter_->time_step(person_->step(), t.dt_s);
      person_->act(t);
      if ((person_->done() || person_->gave_up()) && !finished_) {
        finished_ = true;
        finished_at_s_ = t.t_s;
      }
      if (observer_) observer_(t.t_s);
    });
  } else {
    manual_ = std::make_unique<cell::PickPlaceOperator>(p, params_.manual);
    p.set_operator([this, goal](const runtime::TickInfo& t) {
      if (!finished_) meter_->sample(read_task_sensors(*platform_, home_m_));
      manual_->act(t);
      // The scripted watchmaker has no dial: the cell turns the fingers for them, square with the
      // pin until it is grasped, then with its bore (console input inactive: the haptic master
      // keeps the XYZ coupling; its deadman is the dial's).
      const auto& w = platform_->simulation().gripper->world_state();
      const bool on_tray = w.phase == microworld::PartPhase::kOnSubstrate &&
                           !platform_->simulation().gripper->world().inserted(w);
      teleop::ConsoleInput dial;
      dial.fresh = dial.deadman = !finished_;
      dial.has_theta_goal = true;
      dial.theta_goal_rad = square_yaw_goal(on_tray ? w.part_yaw_rad : goal.target_yaw_rad,
                                            platform_->yaw_target_rad(), goal.yaw_min_rad, goal.yaw_max_rad);
      dial.theta_speed_rad_s = params_.task.rotate_speed_rad_s;
      platform_->set_console_input(dial);
      if ((manual_->done() || manual_->gave_up()) && !finished_) {
        finished_ = true;
        finished_at_s_ = t.t_s;
      }
      if (observer_) observer_(t.t_s);
    });
  }
}

CellCycle::~CellCycle() = default;

bool CellCycle::levelling_now() const noexcept {
  return level_.procedure && !level_.procedure->finished() && task_->step() == AssemblyTask::Step::kInsert &&
         !task_->operator_drives() && !task_->finished();
}

void CellCycle::level_tick(const TaskSensors& s, const runtime::TickInfo& t) {
  SeatLevelling& l = *level_.procedure;
  level_.s += t.dt_s;
  if (l.phase() == SeatLevelling::Phase::kMove) {
    const devices::ParallelPositioner& positioner = *platform_->positioner();
    if (level_.path_ready) {  // planned off the loop since the last tick
      level_.path_ready = false;
      level_.stops = platform_->pose_moves_stopped();
      level_.move_started = platform_->start_pose_move(*level_.path);
      l.move_started(level_.move_started, "the platform refused the levelling move (the tips' floor)");
    } else if (l.wants_move() && !level_.plan_requested) {
      level_.plan_requested = true;  // planned between runs (plan_level_move)
      platform_->stop();
    } else if (level_.move_started && !positioner.moving()) {
      level_.move_started = false;
      l.moved(platform_->pose_moves_stopped() == level_.stops);
    }
  }
  platform_->set_console_input(l.tick(s, t.dt_s));
  if (l.phase() == SeatLevelling::Phase::kDone) task_->set_surface_contact_m(l.contact_height_m());
  if (l.phase() == SeatLevelling::Phase::kFailed) {
    level_.failed = finished_ = true;
    finished_at_s_ = t.t_s;
    platform_->hold();  // the sequence ends with every axis holding
    held_ = true;
  }
}

void CellCycle::plan_level_move() {
  level_.plan_requested = false;
  level_.path.reset();
  const devices::ParallelPositioner& positioner = *platform_->positioner();
  const motion::PlatformTransform from = positioner.reference_pose();
  // The seat as the touches measured it: the platform's floor and refusals take it there.
  platform_->set_seat_on_plate(level_.procedure->seat_on_plate(from));
  try {
    motion::PoseTrajectory path(from, level_.procedure->level_goal(from),
                                platform_->config().parallel_positioner.move);
    if (!motion::check_move(positioner.kinematics(), path).ok)
      return level_.procedure->move_started(false, "the levelling pose is beyond the positioner's reach");
    level_.path.emplace(std::move(path));
    level_.path_ready = true;
  } catch (const std::exception&) {
    level_.procedure->move_started(false, "the levelling pose could not be planned");
  }
}

void CellCycle::hand_over(const runtime::TickInfo& t) {
  if (!person_has_step_ && task_->status() == AssemblyTask::Status::kOperator) {
    person_step_ = task_->step();
    person_->take_over(person_step_, t.t_s);
    person_has_step_ = true;
  }
  if (!person_has_step_) return;
  person_->act(t);  // after the task's tick: the person's console input is the one the coupling takes
  const bool gave_up = person_->gave_up();
  if (person_->step() != person_step_ || gave_up) {
    person_->hand_back();
    person_has_step_ = false;
    ++handovers_;
    task_->hand_back(/*step_done=*/!gave_up);  // given up: the robot does the step from where it is
  }
}

void CellCycle::look() {
  const auto t0 = std::chrono::steady_clock::now();
  const platform::Platform& p = *platform_;
  const platform::CameraScenePose truth = truth_pose(p);
  const PinModel pin{job_.side_m, job_.world.height_m()};
  const TaskSensors s = read_task_sensors(p, home_m_);
  PinSighting seen;
  std::string failed;  // a measure that threw (an image the tracker refused): nothing seen
  try {
    switch (task_->look_wanted()) {
      case AssemblyTask::Look::kSlot:
        seen = camera_->look_slot(truth, pin, job_.nominal_part_m, job_.nominal_part_yaw_rad);
        break;
      case AssemblyTask::Look::kBore:
        seen = camera_->look_bore(truth, job_.target_m, job_.target_yaw_rad);  // where its drawing puts it
        break;
      case AssemblyTask::Look::kHeld: {
        // The pin's top where the grasp left it: the tips grasp_z above its bottom.
        const double grasp_z = AssemblyTask::grasp_height_m(params_.task, assembly_goal(job_));
        seen = camera_->look_held(truth, pin, s.tip_m, s.yaw_rad, s.tip_m.z() - grasp_z + pin.height_m);
        break;
      }
      case AssemblyTask::Look::kAlign: {
        // Over the bore's station, where the bore look looked from.
        const double grasp_z = AssemblyTask::grasp_height_m(params_.task, assembly_goal(job_));
        seen = camera_->look_align(truth, pin, job_.target_m, task_->goal().target_m, s.tip_m, s.yaw_rad,
                                   s.tip_m.z() - grasp_z + pin.height_m);
        break;
      }
      case AssemblyTask::Look::kPlaced:  // from the bore's station too
        seen = camera_->look_placed(truth, pin, job_.target_m, task_->goal().target_m, job_.target_yaw_rad,
                                    pin.height_m - job_.world.hole_depth_m);
        break;
      case AssemblyTask::Look::kNone:
        return;
    }
  } catch (const std::exception& e) {
    seen = PinSighting{};
    failed = std::string("the camera's measure failed: ") + e.what();
  }
  ++looks_;
  if (!seen.found) last_look_miss_ = failed.empty() ? std::string(seen.reason) : failed;
  if (seen.found) {
    ++looks_found_;
    // What the look measured: the bore, or the pin.
    const Eigen::Vector2d truth_xy = task_->look_wanted() == AssemblyTask::Look::kBore
                                         ? Eigen::Vector2d(job_.world.target_m.head<2>())
                                         : Eigen::Vector2d(truth.part_x_m, truth.part_y_m);
    look_error_m_ = std::max(look_error_m_, (seen.part_m.head<2>() - truth_xy).norm());
  }
  AssemblyTask::Sighting sighting;
  sighting.found = seen.found;
  sighting.part_m = seen.part_m;
  sighting.yaw_rad = seen.yaw_rad;
  sighting.error_m = seen.error_m;
  sighting.converged = seen.converged;
  task_->see(sighting);
  look_wall_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void CellCycle::run_for(double duration_s) {
  platform::Platform& p = *platform_;
  const double end = std::min(p.loop().time_s() + duration_s, params_.max_cycle_s);
  while (!finished_ && !p.faulted() && p.loop().time_s() < end - 1e-9) {
    p.run(std::min(1.0, end - p.loop().time_s()));
    if (level_.plan_requested) plan_level_move();
    if (look_requested_) {
      // The look the task asks for (the operator stopped the run): its time passes with the task
      // holding, then the camera looks, off the loop.
      if (params_.camera.look_s > 0.0) p.run(params_.camera.look_s);
      look();
      look_requested_ = false;
    }
  }
  if (finished_ && !settled_) {
    p.run(0.2);  // the stage settles where it was left, and is seen holding there
    settled_ = true;
  }
}

void CellCycle::run_to_end() { run_for(params_.max_cycle_s); }

CycleResult CellCycle::result() const {
  const platform::Platform& p = *platform_;
  const Meter& meter = *meter_;
  CycleResult r;
  r.index = job_.index;
  r.mode = params_.mode;
  r.side_m = job_.side_m;
  r.clearance_m = job_.clearance_m;
  r.part = job_.flat ? "flat" : "pin";
  r.release = std::string(microworld::name(job_.release));
  r.cycle_s = finished_ ? finished_at_s_ : p.loop().time_s();
  const auto& gripper = *p.simulation().gripper;
  const auto& w = gripper.world_state();
  // Down in its bore, or resting on its flat seat within its tolerance, and let go.
  const bool inserted = gripper.world().placed(w);
  const std::string done = job_.flat ? "placed and released" : "inserted and released";
  const std::string not_done = job_.flat ? "the part is not on its seat" : "the pin is not down in its bore";
  r.placement_error_m = gripper.world().placement_error_m(w);
  r.peak_grip_N = meter.peak_grip;
  r.mean_grip_N = meter.gripped_ticks > 0 ? meter.grip_sum / static_cast<double>(meter.gripped_ticks) : 0.0;
  r.peak_contact_N = meter.peak_contact;
  r.grip_violations = meter.grip_over;
  r.contact_violations = meter.contact_over;
  r.neighbour_contacts = w.neighbour_contacts;
  r.path_m = meter.path;
  r.step_s = meter.step_s;
  const auto& teleop = p.teleop();
  Eigen::Vector3d measured;
  for (int i = 0; i < 3; ++i) measured[i] = p.axis(i).position_m();
  // The rotary axis too: its target where it is (hold() takes it there; the person's dial let go
  // leaves it on its last target), within 1 urad (5 nm of arc: the sensor's noise, not a motion).
  const bool rotary_holds = !p.has_rotary() || std::abs(p.yaw_target_rad() - p.yaw_rad()) < 1e-6;
  r.ended_holding = !teleop.engaged && (teleop.slave_target_m - measured).norm() < 1e-6 && rotary_holds;
  if (task_) {
    r.search_tries = task_->search_tries();
    r.confirmations = confirmations_;
    r.handovers = handovers_;
    if (person_) {
      r.master = params_.person.master;
      r.submovements = person_->submovements();
    }
    r.success = task_->status() == AssemblyTask::Status::kSucceeded && inserted;
    if (p.faulted()) {
      r.verdict = "a device faulted";
    } else if (level_.tips && level_.tips->phase() == TipLevellingStep::Phase::kFailed) {
      r.success = false;
      r.verdict = "levelling the tips failed: " + std::string(level_.tips->failure());
    } else if (level_.procedure && level_.procedure->phase() == SeatLevelling::Phase::kFailed) {
      r.success = false;
      r.verdict = "levelling the seat failed: " + std::string(level_.procedure->failure());
    } else if (!finished_) {
      r.verdict =
          "not finished within max_cycle_s (in step " + std::string(AssemblyTask::name(task_->step())) + ")";
    } else if (task_->status() == AssemblyTask::Status::kFailed) {
      r.verdict = "failed in step " + std::string(AssemblyTask::name(task_->step())) + ": " +
                  std::string(task_->failure());
      if (task_->step() == AssemblyTask::Step::kVerify && !last_look_miss_.empty())
        r.verdict += " (" + std::string(last_look_miss_) + ")";
    } else {
      r.verdict = inserted ? done : "the task ended but " + not_done;
    }
    r.ended_holding = r.ended_holding && held_;
  } else if (person_) {
    r.master = params_.person.master;
    r.clutches = person_->clutches();
    r.search_tries = person_->jams();
    r.submovements = person_->submovements();
    r.success = person_->done() && inserted;
    if (p.faulted()) {
      r.verdict = "a device faulted";
    } else if (person_->gave_up()) {
      r.verdict = "the person gave up in step " + std::string(AssemblyTask::name(person_->step())) + ": " +
                  std::string(person_->give_up_reason());
    } else if (!finished_) {
      r.verdict = "not finished within max_cycle_s (in step " +
                  std::string(AssemblyTask::name(person_->step())) + ")";
    } else {
      r.verdict =
          inserted ? "inserted and released" : "the person finished but the pin is not down in its bore";
    }
  } else {
    r.clutches = manual_->clutches();
    r.success = manual_->done() && inserted;
    if (p.faulted()) {
      r.verdict = "a device faulted";
    } else if (manual_->gave_up()) {
      r.verdict = "the operator gave up in phase " +
                  std::string(cell::PickPlaceOperator::name(manual_->failed_phase()));
    } else if (!finished_) {
      r.verdict = "not finished within max_cycle_s";
    } else {
      r.verdict =
          inserted ? "inserted and released" : "the operator finished but the pin is not down in its bore";
    }
  }
  if (level_.tips) {
    const platform::TipLevellingStatus& tips = p.tip_levelling();
    r.tips_levelled = level_.tips->phase() == TipLevellingStep::Phase::kDone;
    r.tip_misalignment_before_m = tips.misalignment_before_m;
    r.tip_misalignment_after_m = tips.misalignment_m;
    r.level_tips_s = level_.tips_s;
  }
  if (level_.procedure) {
    r.seat_levelled = level_.procedure->phase() == SeatLevelling::Phase::kDone;
    r.seat_tilt_before_rad = level_.procedure->tilt_before_rad();
    r.seat_tilt_after_rad = level_.procedure->tilt_rad();
    r.level_rounds = level_.procedure->rounds();
    r.level_s = level_.s;
  }
  r.looks = looks_;
  r.looks_found = looks_found_;
  r.look_error_m = look_error_m_;
  r.look_wall_s = look_wall_s_;
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  return r;
}

CycleResult run_cycle(const AssemblyJob& job, const CellRunParams& params, platform::PlatformConfig base) {
  CellCycle c(job, params, std::move(base));
  c.run_to_end();
  return c.result();
}

std::vector<CycleResult> run_batch(const std::vector<AssemblyJob>& jobs, const CellRunParams& params,
                                   const platform::PlatformConfig& base,
                                   const std::function<void(const CycleResult&)>& progress) {
  params.validate();
  // Refused before the first cycle, not when the first flat part comes up.
  for (const AssemblyJob& j : jobs) require_mode_places(j, params.mode);
  std::vector<CycleResult> out;
  out.reserve(jobs.size());
  for (const AssemblyJob& j : jobs) {
    out.push_back(run_cycle(j, params, base));
    if (progress) progress(out.back());
  }
  return out;
}

}  // namespace mc::cell
