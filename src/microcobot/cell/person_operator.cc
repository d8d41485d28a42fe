#include "microcobot/cell/person_operator.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "microcobot/core/error.h"
#include "microcobot/microworld/pick_place_world.h"

namespace mc::cell {

void PersonOperatorParams::validate() const {
  require(master == "haptic" || master == "console" || master == "click", "master",
          "must be haptic, console or click, got '" + master + "'");
  require(std::isfinite(screen_px_per_m) && screen_px_per_m >= 1e3 && screen_px_per_m <= 1e9,
          "screen_px_per_m", "must be within [1e3, 1e9] px/m", screen_px_per_m);
  require(std::isfinite(min_click_px) && min_click_px >= 1.0 && min_click_px <= 100.0, "min_click_px",
          "must be within [1, 100] px", min_click_px);
  person.validate();
  require_positive(pin_tolerance_m, "pin_tolerance_m");
  require_positive(bore_tolerance_m, "bore_tolerance_m");
  require_positive(assisted_tolerance_m, "assisted_tolerance_m");
  require_non_negative(assist_vision_sd_m, "assist_vision_sd_m");
  require_positive(z_tolerance_m, "z_tolerance_m");
  require_non_negative(yaw_vision_sd_rad, "yaw_vision_sd_rad");
  require(yaw_tolerance_rad > 0.0 && yaw_tolerance_rad <= 0.2, "yaw_tolerance_rad",
          "must be within (0, 0.2] rad", yaw_tolerance_rad);
  require_non_negative(assist_yaw_sd_rad, "assist_yaw_sd_rad");
  require_positive(still_m, "still_m");
  require(still_window_s > 0.0 && still_window_s <= 0.2, "still_window_s", "must be within (0, 0.2] s",
          still_window_s);
  require_positive(jam_margin_m, "jam_margin_m");
  require_positive(jam_retreat_m, "jam_retreat_m");
  require_positive(press_m, "press_m");
  require_positive(hand_limit_m, "hand_limit_m");
  require_positive(pinch_m_s, "pinch_m_s");
  require_positive(max_pinch_m, "max_pinch_m");
  require_positive(felt_grip_N, "felt_grip_N");
  require_positive(slider_m_s, "slider_m_s");
  require_positive(grip_seen_N, "grip_seen_N");
  require_positive(joystick_travel_m, "joystick_travel_m");
  require_positive(stalled_s, "stalled_s");
  require_positive(assisted_pace_m_s, "assisted_pace_m_s");
  require_positive(step_timeout_s, "step_timeout_s");
  require(std::isfinite(shake_hold_s) && shake_hold_s > 0.0 && shake_hold_s <= 5.0, "shake_hold_s",
          "must be within (0, 5] s", shake_hold_s);
  require(max_jams >= 1, "max_jams", "must be at least 1", max_jams);
}

namespace {

double operator_rate_Hz(const platform::PlatformConfig& c) {
  return c.loop.base_rate_Hz / c.loop.operator_divisor;
}

}  // namespace

PersonOperator::PersonOperator(platform::Platform& platform, const PersonOperatorParams& params,
                               const AssemblyTaskParams& task, const AssemblyGoal& goal, bool assisted,
                               std::uint64_t seed)
    : platform_(platform),
      sim_(platform.simulation()),
      p_(params),
      goal_(goal),
      assisted_(assisted),
      haptic_(params.master == "haptic"),
      click_(params.master == "click"),
      rng_(seed),
      xy_(params.person, rng_),
      z_(params.person, rng_),
      cursor_(params.person, rng_),
      yaw_(params.person, rng_),
      tremor_(params.person, operator_rate_Hz(platform.config()), seed ^ 0x7472656d6f72ULL),
      base_scale_(platform.config().teleop.motion_scale) {
  p_.validate();
  task.validate();
  require(sim_.gripper != nullptr && sim_.haptic != nullptr && sim_.tweezers != nullptr, "microworld",
          "the simulated person needs the pick-and-place scene's simulated devices");
  grasp_z_ = AssemblyTask::grasp_height_m(task, goal);  // a flat part at half its thickness
  roll_rad_ = task.roll_rad;
  safe_z_ = std::max(goal.part_height_m, goal.tallest_neighbour_m) + task.clearance_height_m;
  carry_z_ = grasp_z_ + goal.tallest_neighbour_m + task.clearance_height_m;
  inserted_z_ = grasp_z_ - goal.hole_depth_m;
  const Eigen::Vector3d tip = sim_.gripper->tip_position_m();
  xy_.reset(
      haptic_ ? Eigen::Vector2d(sim_.haptic->operator_hand().hand_m.x, sim_.haptic->operator_hand().hand_m.y)
              : Eigen::Vector2d(tip.head<2>()),
      0.0);
  z_.reset({tip.z(), 0.0}, 0.0);
  cursor_scale_ = p_.screen_px_per_m;
  cursor_.reset(tip.head<2>() * cursor_scale_, 0.0);  // on the tool, where the view is centred
  require(!(click_ && assisted), "master",
          "click: the console's click-to-go is for manual runs (the click is the platform's move already)");
  yaw_.reset({platform.yaw_target_rad(), 0.0}, 0.0);
  turn_.arrived_rad = task.yaw_tolerance_rad;
  slider_ = goal.open_m;
  tips_.window_ticks =
      std::clamp(static_cast<int>(std::lround(p_.still_window_s * operator_rate_Hz(platform.config()))), 1,
                 kHistory - 1);
  // The cell's vision finds the pin on the tray (assisted): where the guidance takes the tips.
  pin_seen_ = seen(sim_.gripper->world_state().part_m.head<2>(), p_.assist_vision_sd_m);
}

void PersonOperator::enter(Step s, double t) noexcept {
  step_ = s;
  step_t0_ = t;
  insertion_.rising = false;
  turn_.rotated = false;
  held_since_ = -1.0;
  insertion_.lowest_z_m = std::numeric_limits<double>::infinity();
  insertion_.lowest_t_s = t;
  release_.stage = 0;
  release_.shaking = false;
}

void PersonOperator::take_over(Step s, double t) noexcept {
  const devices::SimulatedGripper& g = *sim_.gripper;
  const Eigen::Vector3d tip = g.tip_position_m(), part = g.world_state().part_m;
  xy_.reset(tip.head<2>(), t);
  z_.reset({tip.z(), 0.0}, t);
  cursor_.reset(tip.head<2>() * cursor_scale_, t);
  yaw_.reset({platform_.yaw_target_rad(), 0.0}, t);
  slider_ = std::clamp(platform_.teleop().gripper_opening_m, 0.0, goal_.open_m);
  if (g.grip_force_N() > 0.0) {  // held: where its bottom is below the tips, and its place in them
    rim_z_ = tip.z() - (part.z() - 0.5 * goal_.part_height_m);
    pin_offset_seen_ = seen((part - tip).head<2>(), p_.assist_vision_sd_m);
  }
  tips_.count = 0;
  gave_up_ = false;
  enter(s, t);
}

void PersonOperator::give_up(const char* why) noexcept {
  gave_up_ = true;
  reason_ = why;
  let_go();
}

void PersonOperator::let_go() noexcept {
  hand_.deadman = false;
  hand_.clutch = false;
  hand_.jog_m_s = 0.0;
  sim_.haptic->set_operator(hand_);
  console_ = {};
  platform_.set_console_input(console_);  // the dial's deadman too
  platform_.set_fixtures({});
}

Eigen::Vector2d PersonOperator::seen(const Eigen::Vector2d& p, double sd_m) noexcept {
  const double sd = sd_m >= 0.0 ? sd_m : p_.person.vision_sd_m;
  // One draw per statement (a call's arguments have no order, GCC's was y first): a seed gives the
  // same person whatever the compiler.
  const double seen_y = rng_.normal(0.0, sd), seen_x = rng_.normal(0.0, sd);
  return p + Eigen::Vector2d(seen_x, seen_y);
}

bool PersonOperator::tool_still() const noexcept {
  if (tips_.count <= tips_.window_ticks) return false;
  const Eigen::Vector3d& now = tips_.back(0);
  const Eigen::Vector3d& then = tips_.back(tips_.window_ticks);
  return (now - then).norm() < p_.still_m;
}

void PersonOperator::assist() noexcept {
  teleop::FixtureSet f;
  f.level = 1.0;
  f.guide = true;
  // The working heights as stops (the same heights the automatic task uses): the person rolls the
  // wheel (or pushes the joystick) into the stop's capture and the slave sits at the height.
  // None while inserting and releasing: the descent is the person's, felt or seen.
  f.height = step_ != Step::kInsert && step_ != Step::kRelease;
  f.height_z_m = step_height_z();
  switch (step_) {
    case Step::kApproach:
    case Step::kAlign:
    case Step::kDescend:
    case Step::kGrasp:
    case Step::kLift:
      f.guide_xy_m = pin_seen_;  // the tips onto the pin vision found
      break;
    case Step::kTransport:
    case Step::kRotate:
    case Step::kInsert:
    case Step::kRelease:
    case Step::kRetract:
      // The carried pin onto its bore's axis, and the funnel round the rim; held through the
      // release and the retract, so that the fingers open and rise on the axis (the guidance's
      // pull on the handle, let go, would spring the hand back by micrometres of slave).
      f.guide_xy_m = goal_.target_m - pin_offset_seen_;
      f.funnel = true;
      f.rim_z_m = rim_z_;
      f.funnel_radius_m = 0.5 * goal_.clearance_m;
      break;
    default:
      f = {};
      break;
  }
  f.keep_outs = goal_.keep_outs;  // the neighbours' forbidden regions, whatever the step
  f.keep_out_count = goal_.keep_out_count;
  platform_.set_fixtures(f);
}

void PersonOperator::act(const runtime::TickInfo& tick) noexcept {
  const double t = tick.t_s, dt = tick.dt_s;
  if (step_ == Step::kDone || gave_up_) return;
  if (t - step_t0_ > p_.step_timeout_s) {
    give_up("a step took the person longer than step_timeout_s");
    return;
  }
  const devices::SimulatedGripper& g = *sim_.gripper;
  const Eigen::Vector3d tip = g.tip_position_m();
  const Eigen::Vector3d part = g.world_state().part_m;
  const devices::Vec3 c = g.contact_force_N();
  const Eigen::Vector3d contact(c.x, c.y, c.z);
  tool_xy_ = tip.head<2>();
  tips_.push(tip);
  hand_.deadman = true;
  switch (step_) {
    case Step::kApproach:
      if (tip.z() < safe_z_ - p_.z_tolerance_m) {
        climb(safe_z_, tip.z(), p_.z_tolerance_m, t, aim_height_width());
      } else if (steer(part.head<2>() - tip.head<2>(), p_.pin_tolerance_m, t,
                       aim_width(p_.pin_tolerance_m))) {
        enter(Step::kAlign, t);
      }
      break;
    case Step::kAlign: {
      // The fingers' flats square with the pin's faces.
      const double pin_yaw = g.world_state().part_yaw_rad;
      if (turn(microworld::wrap_quarter_turn(pin_yaw - g.yaw_rad()), t)) enter(Step::kDescend, t);
      break;
    }
    case Step::kDescend:
      if (climb(grasp_z_, tip.z(), p_.z_tolerance_m, t, aim_height_width())) enter(Step::kGrasp, t);
      break;
    case Step::kGrasp: {
      const bool held =
          haptic_ ? platform_.teleop().finger_force_N >= p_.felt_grip_N : g.grip_force_N() >= p_.grip_seen_N;
      if (held && held_since_ < 0.0) held_since_ = t;
      // Closing until the grip is told, and a reaction time more before the fingers stop.
      const bool closing = held_since_ < 0.0 || t < held_since_ + p_.person.reaction_time_s;
      if (closing) {
        if (haptic_) {
          pinch_ = std::min(p_.max_pinch_m, pinch_ + p_.pinch_m_s * dt);
        } else {
          slider_ = std::max(0.0, slider_ - p_.slider_m_s * dt);
        }
      }
      if (held_since_ >= 0.0 && t >= held_since_ + 2.0 * p_.person.reaction_time_s) {
        rim_z_ = tip.z() - (part.z() - 0.5 * goal_.part_height_m);
        enter(Step::kLift, t);
      } else if (!held && (haptic_ ? pinch_ >= p_.max_pinch_m : slider_ <= 0.0)) {
        give_up("the fingers closed on nothing");
      }
      break;
    }
    case Step::kLift:
      if (climb(carry_z_, tip.z(), p_.z_tolerance_m, t, aim_height_width())) {
        // The pin's place in the fingers once it is up, as vision sees it (assisted).
        pin_offset_seen_ = seen((part - tip).head<2>(), p_.assist_vision_sd_m);
        enter(Step::kTransport, t);
      }
      break;
    case Step::kTransport:
      if (steer(goal_.target_m - part.head<2>(), p_.bore_tolerance_m, t, aim_width(p_.bore_tolerance_m)))
        enter(Step::kRotate, t);
      break;
    case Step::kRotate:
      // The pin's faces square with the bore's; it turns about the tips, so it is aimed again after.
      if (!turn_.rotated) {
        if (turn(bore_misalignment(), t)) {
          turn_.rotated = true;
          pin_offset_seen_ = seen((part - tip).head<2>(), p_.assist_vision_sd_m);  // vision looks again
        }
      } else if (steer(goal_.target_m - part.head<2>(), p_.bore_tolerance_m, t,
                       aim_width(p_.bore_tolerance_m))) {
        enter(Step::kInsert, t);
      }
      break;
    case Step::kInsert: {
      if (insertion_.rising) {
        // Off the rim: up, then a fresh look and aim before going down again.
        if (climb(rim_z_ + p_.jam_retreat_m, tip.z(), p_.z_tolerance_m, t) &&
            steer(goal_.target_m - part.head<2>(), p_.bore_tolerance_m, t, aim_width(p_.bore_tolerance_m)) &&
            turn(bore_misalignment(), t))
          insertion_.rising = false;
        break;
      }
      // The plate pushing the pin up, felt (haptic: through the handle's force; console: on the
      // display) well above the bore's depth: the pin is on the rim. The person stops rolling
      // down at once and, a reaction later, backs off and looks again.
      const bool touching = contact.z() >= p_.person.feel_contact_N;
      if (touching && tip.z() > inserted_z_ + p_.jam_margin_m) {
        if (++jams_ > p_.max_jams) {
          give_up("the pin kept landing on the rim");
          return;
        }
        z_.reset({tip.z(), 0.0}, t);
        insertion_.rising = true;
        insertion_.lowest_z_m = std::numeric_limits<double>::infinity();
        break;
      }
      // Down onto the bore's floor: aimed a press below it, done when the floor is felt there,
      // or when the pin, well into its bore, is seen going no lower.
      climb(inserted_z_ - p_.press_m, tip.z(), p_.z_tolerance_m, t);
      if (tip.z() < insertion_.lowest_z_m - p_.still_m) {
        insertion_.lowest_z_m = tip.z();
        insertion_.lowest_t_s = t;
      }
      const bool in_bore = tip.z() < rim_z_ - 0.5 * goal_.hole_depth_m;
      if ((touching && tip.z() <= inserted_z_ + p_.jam_margin_m) ||
          (in_bore && t - insertion_.lowest_t_s > p_.stalled_s))
        enter(Step::kRelease, t);
      break;
    }
    case Step::kRelease:
      if (haptic_) {
        pinch_ = std::max(0.0, pinch_ - p_.pinch_m_s * dt);
      } else {
        slider_ = std::min(goal_.open_m, slider_ + p_.slider_m_s * dt);
      }
      if (release_.stage == 0 && g.opening_m() > 0.9 * goal_.open_m) {
        release_.stage = goal_.flat_seat && goal_.release != microworld::ReleaseStrategy::kOpen ? 1 : 2;
        release_.t0_s = t;
        // The haptic master has no burst: its person rolls.
        const bool roll = goal_.release == microworld::ReleaseStrategy::kRoll || haptic_;
        const double fingers = platform_.yaw_rad();
        release_.roll_goal_rad =
            roll ? (fingers + roll_rad_ <= goal_.yaw_max_rad ? fingers + roll_rad_ : fingers - roll_rad_)
                 : std::numeric_limits<double>::quiet_NaN();
      }
      if (release_.stage == 1) {
        if (std::isnan(release_.roll_goal_rad)) {
          release_.shaking = t - release_.t0_s < p_.shake_hold_s;  // Shake held, then let go
          if (!release_.shaking) release_.stage = 2;
        } else if (turn_by(release_.roll_goal_rad - platform_.yaw_rad(), t)) {
          release_.stage = 2;
        }
      }
      if (release_.stage == 2) enter(Step::kRetract, t);
      break;
    case Step::kRetract:
      if (climb(safe_z_, tip.z(), p_.z_tolerance_m, t, aim_height_width())) {
        enter(Step::kDone, t);
        let_go();
        return;
      }
      break;
    default:
      break;
  }
  if (assisted_) assist();
  apply(t);
}

double PersonOperator::step_height_z() const noexcept {
  switch (step_) {
    case Step::kDescend:
    case Step::kGrasp:
      return grasp_z_;
    case Step::kLift:
    case Step::kTransport:
    case Step::kRotate:
      return carry_z_;
    default:
      return safe_z_;  // approach, retract (and the steps without a stop)
  }
}

void PersonOperator::apply(double t) noexcept {
  const Eigen::Vector2d tremor = tremor_.next();
  // The console's dial (both masters: the haptic handle has no rotation): the rotor follows the
  // dial's angle; with shared control, the platform's own turn.
  console_.fresh = console_.deadman = true;
  console_.has_theta_goal = true;
  console_.theta_goal_rad = assisted_ && turn_.under_way ? turn_.goal_rad : yaw_.position(t).x();
  console_.theta_speed_rad_s = platform_.config().stage.rotary.max_speed_rad_s;
  if (haptic_) {
    const Eigen::Vector2d h = xy_.position(t) + tremor;
    hand_.hand_m = {h.x(), h.y()};
    hand_.jog_m_s = z_.velocity(t).x();
    sim_.haptic->set_operator(hand_);
    sim_.tweezers->set_operator_closing(pinch_);
    console_.active = false;  // the handle holds the XYZ coupling
    platform_.set_console_input(console_);
    return;
  }
  // The joystick: the person's intended motion as a rate, its deflection trembling too.
  // (The platform scales the joystick's speed by the shared control's gain; the person planned
  // for it, steer().)
  const double per_m = platform_.config().teleop.console_max_speed_m_s / p_.joystick_travel_m;
  console_.active = console_.fresh = console_.deadman = true;
  console_.has_goal = false;
  console_.velocity_m_s.head<2>() = xy_.velocity(t) + per_m * tremor;
  console_.velocity_m_s.z() = z_.velocity(t).x();
  if (click_) {
    // The plane is the clicks': the stage goes to the last one at the person's pace (a click and a
    // jog at once: the page drops the click, so the person does one at a time).
    console_.velocity_m_s.head<2>().setZero();
    if (click_goal_.active) {
      console_.has_goal = true;
      console_.goal_m = click_goal_.at_m;
      console_.goal_speed_m_s = p_.person.stage_pace_m_s;
      console_.velocity_m_s.z() = 0.0;
    }
  }
  console_.has_gripper = true;
  console_.gripper_opening_m = slider_;
  console_.gripper_shake = release_.shaking;
  platform_.set_console_input(console_);
}

}  // namespace mc::cell
