#include "microcobot/cell/seat_levelling.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "microcobot/core/error.h"

namespace mc::cell {
namespace {

constexpr double kThere_m = 1e-6;  // a travel's goal reached: the touches do not depend on it
/// The touches' directions from the bore: three of the four diagonals (header).
/// The fourth touch is the first's again: the drift between them is the part's slip in the fingers.
constexpr double kTouchAngles_rad[4] = {M_PI / 4, 3 * M_PI / 4, 5 * M_PI / 4, M_PI / 4};

/// The smallest rotation taking unit vector `from` to unit vector `to`.
Eigen::Matrix3d turn(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  return Eigen::Quaterniond::FromTwoVectors(from, to).toRotationMatrix();
}

}  // namespace

void SeatLevellingParams::validate() const {
  require(mode == "auto" || mode == "on" || mode == "off", "level_seat.mode",
          "must be auto, on or off (got '" + mode + "')");
  require(std::isfinite(probe_radius_m) && probe_radius_m >= 100e-6 && probe_radius_m <= 2e-3,
          "level_seat.probe_radius_m", "must be within [0.1, 2] mm", probe_radius_m);
  require(std::isfinite(probe_speed_m_s) && probe_speed_m_s > 0.0 && probe_speed_m_s <= 200e-6,
          "level_seat.probe_speed_m_s", "must be within (0, 200] um/s", probe_speed_m_s);
  require(std::isfinite(approach_speed_m_s) && approach_speed_m_s > 0.0 && approach_speed_m_s <= 1e-3,
          "level_seat.approach_speed_m_s", "must be within (0, 1] mm/s", approach_speed_m_s);
  require(std::isfinite(travel_speed_m_s) && travel_speed_m_s > 0.0 && travel_speed_m_s <= 2e-3,
          "level_seat.travel_speed_m_s", "must be within (0, 2] mm/s", travel_speed_m_s);
  require(std::isfinite(search_from_m) && search_from_m >= 0.0 && search_from_m <= 1e-3,
          "level_seat.search_from_m", "must be within [0, 1] mm", search_from_m);
  require(std::isfinite(max_travel_m) && max_travel_m > 0.0 && max_travel_m <= 2e-3,
          "level_seat.max_travel_m", "must be within (0, 2] mm", max_travel_m);
  require(std::isfinite(contact_threshold_N) && contact_threshold_N > 0.0 && contact_threshold_N <= 1e-3,
          "level_seat.contact_threshold_N", "must be within (0, 1] mN", contact_threshold_N);
  require(std::isfinite(touch_speed_m_s) && touch_speed_m_s > 0.0 && touch_speed_m_s <= probe_speed_m_s,
          "level_seat.touch_speed_m_s", "must be within (0, level_seat.probe_speed_m_s]", touch_speed_m_s);
  require(std::isfinite(retouch_m) && retouch_m > 0.0 && retouch_m <= 50e-6, "level_seat.retouch_m",
          "must be within (0, 50] um", retouch_m);
  require(std::isfinite(lift_m) && lift_m > 0.0 && lift_m <= 500e-6, "level_seat.lift_m",
          "must be within (0, 500] um", lift_m);
  require(std::isfinite(tolerance_rad) && tolerance_rad > 0.0 && tolerance_rad <= 0.02,
          "level_seat.tolerance_rad", "must be within (0, 0.02] rad", tolerance_rad);
  require(max_rounds >= 1 && max_rounds <= 10, "level_seat.max_rounds", "must be within [1, 10]", max_rounds);
}

SeatLevelling::SeatLevelling(const SeatLevellingParams& params, const Eigen::Vector2d& bore_xy_m,
                             double contact_z_m)
    : p_(params), bore_(bore_xy_m), contact_z_(contact_z_m) {
  p_.validate();
  require(bore_.allFinite() && std::isfinite(contact_z_), "level_seat",
          "the bore and the contact height must be finite");
  out_.active = out_.fresh = out_.deadman = true;
}

Eigen::Vector2d SeatLevelling::touch_point(int i) const noexcept {
  const double a = kTouchAngles_rad[std::clamp(i, 0, 3)];
  return bore_ + p_.probe_radius_m * Eigen::Vector2d(std::cos(a), std::sin(a));
}

bool SeatLevelling::head_for(const Eigen::Vector3d& goal, double speed, const TaskSensors& s) noexcept {
  out_.has_goal = true;
  out_.goal_m = goal;
  out_.goal_speed_m_s = speed;
  return (s.tip_m - goal).norm() <= kThere_m;
}

void SeatLevelling::back_off(const TaskSensors& s, double by_m, Descent then) noexcept {
  back_to_z_ = std::min(start_.z(), s.tip_m.z() + by_m);
  phase_ = Phase::kBackOff;
  descent_ = then;
  released_ = false;
  if (then == Descent::kSlow) slow_from_z_ = back_to_z_;
}

void SeatLevelling::fail(const char* why) noexcept {
  phase_ = Phase::kFailed;
  failure_ = why;
  out_.deadman = false;  // the platform holds
  out_.has_goal = false;
  out_.velocity_m_s.setZero();
}

const teleop::ConsoleInput& SeatLevelling::tick(const TaskSensors& s, double /*dt_s*/) noexcept {
  if (!started_) {
    start_ = s.tip_m;
    started_ = true;
    // The fingers keep the grip they have (the task's command), whatever the TéléTweez does.
    out_.has_gripper = std::isfinite(s.gripper_command_m);
    out_.gripper_opening_m = out_.has_gripper ? s.gripper_command_m : 0.0;
  }
  const double travel_z = start_.z();
  switch (phase_) {
    case Phase::kRise: {
      const Eigen::Vector3d up(s.tip_m.x(), s.tip_m.y(), travel_z);
      if (!head_for(up, p_.travel_speed_m_s, s)) break;
      if (point_ < kTouches) {
        phase_ = Phase::kTravel;
      } else {  // the round's touches are in: the plate moves with the part up at the travel height
        hold_ = up;
        fit();
      }
      break;
    }
    case Phase::kTravel: {
      const Eigen::Vector2d xy = touch_point(point_);
      if (head_for({xy.x(), xy.y(), travel_z}, p_.travel_speed_m_s, s)) {
        phase_ = Phase::kDescend;
        descent_ = Descent::kFast;
        released_ = false;
        // The round's first touch is looked for from over the nominal contact; the others from
        // lift_m over the first (a tilt within 5 deg changes the seat's height by less between
        // the touches).
        fast_end_z_ =
            std::min(travel_z, point_ == 0 ? contact_z_ + p_.search_from_m : touches_[0].z() + p_.lift_m);
      }
      break;
    }
    case Phase::kDescend: {
      const Eigen::Vector2d xy = touch_point(point_);
      const bool pressed = s.contact_N.z() > p_.contact_threshold_N;
      if (pressed && !released_) {  // still on the seat since the last touch: further up first
        back_off(s, p_.retouch_m, descent_);
        break;
      }
      released_ = released_ || !pressed;
      if (pressed) {
        switch (descent_) {
          case Descent::kFast:  // touched early: back up, and find it at the probe's speed
            back_off(s, p_.lift_m, Descent::kSlow);
            break;
          case Descent::kSlow:  // found: back up a little, and touch again slowly to measure it
            back_off(s, p_.retouch_m, Descent::kFine);
            break;
          case Descent::kFine:
            touches_[static_cast<std::size_t>(point_)] = s.tip_m;
            ++point_;
            phase_ = Phase::kRise;
            break;
        }
        break;
      }
      if (descent_ == Descent::kFast) {
        if (head_for({xy.x(), xy.y(), fast_end_z_}, p_.approach_speed_m_s, s)) {
          descent_ = Descent::kSlow;
          slow_from_z_ = s.tip_m.z();
        }
        break;
      }
      if (s.tip_m.z() < slow_from_z_ - p_.max_travel_m + kThere_m)
        return fail("no touch of the seat within level_seat.max_travel_m"), out_;
      head_for({xy.x(), xy.y(), slow_from_z_ - p_.max_travel_m},
               descent_ == Descent::kSlow ? p_.probe_speed_m_s : p_.touch_speed_m_s, s);
      break;
    }
    case Phase::kBackOff: {
      const Eigen::Vector2d xy = touch_point(point_);
      if (head_for({xy.x(), xy.y(), back_to_z_}, p_.approach_speed_m_s, s)) phase_ = Phase::kDescend;
      break;
    }
    case Phase::kMove:  // the tool holds where the rise left it while the plate turns
      head_for(hold_, p_.travel_speed_m_s, s);
      break;
    case Phase::kReturn:  // at the travel height already
      if (head_for(start_, p_.travel_speed_m_s, s)) phase_ = Phase::kDone;
      break;
    case Phase::kDone:
    case Phase::kFailed:
      break;
  }
  return out_;
}

void SeatLevelling::fit() noexcept {
  // Each touch pushes the part up in the fingers a little (its press passes the grip's hold for a
  // moment): the first point touched again measures the whole slip, shared out over the touches
  // in order as a linear drift.
  const double drift = touches_[3].z() - touches_[0].z();
  std::array<Eigen::Vector3d, 3> t{};
  for (std::size_t k = 0; k < 3; ++k)
    t[k] = touches_[k] - Eigen::Vector3d(0.0, 0.0, drift * static_cast<double>(k) / 3.0);
  Eigen::Vector3d n = (t[1] - t[0]).cross(t[2] - t[0]);
  if (!(n.norm() > 0.0) || !n.allFinite()) return fail("the touches do not span a plane");
  n.normalize();
  if (n.z() < 0.0) n = -n;
  normal_ = n;
  // The plane over the bore, as the last touch (the first point again) stands on it.
  const Eigen::Vector3d& last = touches_[3];
  contact_height_ = last.z() - (n.x() * (bore_.x() - last.x()) + n.y() * (bore_.y() - last.y())) / n.z();
  tilt_ = std::acos(std::clamp(n.z(), -1.0, 1.0));
  if (rounds_ == 0) tilt_before_ = tilt_;
  ++rounds_;
  point_ = 0;
  move_started_ = false;
  if (tilt_ <= p_.tolerance_rad) {
    phase_ = Phase::kReturn;
  } else if (rounds_ >= p_.max_rounds) {
    fail("the seat is still tilted beyond level_seat.tolerance_rad after level_seat.max_rounds rounds");
  } else {
    phase_ = Phase::kMove;
  }
}

motion::PlatformTransform SeatLevelling::level_goal(const motion::PlatformTransform& plate) const noexcept {
  // About the plate's centre, which the seat's surface passes through (header): the seat's points
  // keep the height of its centre.
  motion::PlatformTransform goal;
  goal.R = turn(normal_, Eigen::Vector3d::UnitZ()) * plate.R;
  goal.d = plate.d;
  return goal;
}

motion::PlatformTransform SeatLevelling::seat_on_plate(
    const motion::PlatformTransform& plate) const noexcept {
  // The seat as measured, in the world: tilted to the normal with the plate's heading, through the
  // plate's centre (its drawing); in the plate's frame, M = T_plate^-1 T_seat.
  motion::PlatformTransform m;
  m.R = plate.R.transpose() * turn(plate.R.col(2), normal_) * plate.R;
  return m;
}

void SeatLevelling::move_started(bool started, const char* why) noexcept {
  if (phase_ != Phase::kMove) return;
  if (!started) return fail(why);
  move_started_ = true;
}

void SeatLevelling::moved(bool arrived) noexcept {
  if (phase_ != Phase::kMove || !move_started_) return;
  if (!arrived) return fail("the plate's levelling move stopped short");
  phase_ = Phase::kRise;
}

}  // namespace mc::cell
