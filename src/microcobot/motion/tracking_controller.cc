#include "microcobot/motion/tracking_controller.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "microcobot/core/error.h"

namespace mc::motion {

using stickslip::Direction;

void TrackingParams::validate() const {
  require_positive(control_rate_Hz, "tracking.control_rate_Hz");
  require_in_range(low_V, 0.0, 100.0, "tracking.low_V");
  require_in_range(high_V, 0.0, 100.0, "tracking.high_V");
  require(high_V - low_V >= 20.0, "tracking.high_V", "must exceed low_V by >= 20 V (an edge must slip)",
          high_V - low_V);
  require_in_range(sprint_low_V, 0.0, low_V, "tracking.sprint_low_V");
  require_positive(sprint_velocity_m_s, "tracking.sprint_velocity_m_s");
  require_positive(sprint_lag_m, "tracking.sprint_lag_m");
  require_in_range(sprint_horizon_s, 0.0, 0.1, "tracking.sprint_horizon_s");
  require_in_range(damp_gain, 0.0, 2.0, "tracking.damp_gain");
  require(damp_Hz > 0.0 && damp_Hz < 0.45 * control_rate_Hz, "tracking.damp_Hz",
          "must lie in (0, 0.45 control_rate_Hz)", damp_Hz);
  require_in_range(damp_q, 0.2, 20.0, "tracking.damp_q");
  require_in_range(damp_lag_ticks, -1.0, 1.0, "tracking.damp_lag_ticks");
  require_in_range(guard_V, 0.0, 10.0, "tracking.guard_V");
  require(unload_V >= 0.0 && unload_V <= high_V - low_V - 10.0, "tracking.unload_V",
          "must be in [0, high_V - low_V - 10]", unload_V);
  require_non_negative(edge_margin_m, "tracking.edge_margin_m");
  require_in_range(edge_split_s, 0.0, 5e-3, "tracking.edge_split_s");
  require_in_range(edge_ready_V, 0.0, 50.0, "tracking.edge_ready_V");
  require_in_range(lead_fraction, 0.0, 1.0, "tracking.lead_fraction");
  require_positive(lead_window_m, "tracking.lead_window_m");
  require_positive(catchup_s, "tracking.catchup_s");
  require_non_negative(settle_s, "tracking.settle_s");
  require(settle_s < catchup_s, "tracking.settle_s", "must be shorter than catchup_s", settle_s);
  require_non_negative(ki_1_s, "tracking.ki_1_s");
  require_in_range(kp, -1.0, 1.0, "tracking.kp");
  require_in_range(backslip_gain, 0.0, 1.0, "tracking.backslip_gain");
  require_positive(in_position_m, "tracking.in_position_m");
  require_positive(filter_s, "tracking.filter_s");
  require(powerup_V == 0.0 || (powerup_V >= low_V && powerup_V <= high_V), "tracking.powerup_V",
          "must be 0 (off) or within low_V..high_V", powerup_V);
  require(powerup_unload_V >= 0.0 && powerup_V + powerup_unload_V <= high_V, "tracking.powerup_unload_V",
          "must be >= 0 with powerup_V + powerup_unload_V <= high_V", powerup_unload_V);
  require_non_negative(powerup_settle_s, "tracking.powerup_settle_s");
  require_positive(powerup_ready_m, "tracking.powerup_ready_m");
}

TrackingController::TrackingController(const TrackingParams& p, const stickslip::StickSlipParams& model,
                                       const StepMap& map)
    : p_((p.validate(), p)),
      map_(map),
      pi_((model.validate(), model.hysteresis)),
      g_(model.pe.static_gain_m_V),
      slew_(model.drive.slew_rate_V_s),
      min_V_(model.drive.min_V),
      dt_c_(1.0 / p.control_rate_Hz),
      obs_(stickslip::make_pi_state(model.hysteresis, 0.0)),
      band_pass_(p_.damp_Hz, p_.damp_q, p_.control_rate_Hz) {
  require(p.sprint_low_V >= model.drive.min_V && p.high_V <= model.drive.max_V,
          "tracking.sprint_low_V/high_V", "must lie within the amplifier's range (drive.min_V..max_V)");
  backslip_.set(p_.unload_V > 0.0 ? p_.backslip_m : predicted_backslip_m(1000.0, Direction::kForward),
                p_.unload_V > 0.0 ? p_.backslip_m : predicted_backslip_m(1000.0, Direction::kBackward));
  op_.amplitude_V = p_.high_V - p_.low_V;
  reset(0.0, 0.0);  // the amplifier at power-up
}

double TrackingController::pe_displacement_m(double u_V) const noexcept {
  return g_ * stickslip::pi_peek(pi_, obs_, u_V);
}

double TrackingController::inverse_V(double y_m) const noexcept {
  return stickslip::pi_peek_inverse(pi_, obs_, y_m / g_, floor_V_, p_.high_V);
}

double TrackingController::predicted_backslip_m(double frequency_Hz, Direction d) const noexcept {
  const double a = p_.high_V - p_.low_V;
  return std::max(0.0, map_.reach_m(a, frequency_Hz, d) - map_.step_m(a, frequency_Hz, d));
}

double TrackingController::flyback_frequency_Hz(double v_m_s, double a, Direction d) const noexcept {
  // f = |v| / s(A, f, d): the step map's inverse at the operating point (a fixed point in f).
  double f = 1000.0;
  for (int i = 0; i < 4; ++i) {
    const double s = map_.step_m(a, f, d);
    if (s <= 0.0) break;
    f = std::clamp(std::abs(v_m_s) / s, 1.0, 2000.0);
  }
  return f;
}

void TrackingController::reset(double x_m, double u_V) noexcept {
  // A drive below the ramp's range (the amplifier at 0 V at power-up) is not jumped into range:
  // that would move the slider by g low_V at once; the ramp may use the voltages below until it
  // first reaches low_V.
  floor_V_ = std::clamp(u_V, min_V_, p_.low_V);
  u_V = std::clamp(u_V, floor_V_, p_.high_V);
  // Drive the observer to u_V from the bottom of the range (no allocation).
  stickslip::pi_update(pi_, obs_, p_.low_V);
  stickslip::pi_update(pi_, obs_, u_V);
  u_ = u_cmd_ = u_prev_cmd_ = u_V;
  ref_ = ReferenceSample{x_m, 0.0, 0.0};
  y_anchor_ = pe_displacement_m(u_V);
  r_anchor_ = x_m;
  catch_up_.reset();
  since_edge_s_ = 1.0;
  integ_ = 0.0;
  x_filt_ = x_m;
  have_x_ = true;
  edge_ = pending_anchor_ = sprint_ = false;
  backslip_.forget_outcome();
  stopped_ = false;
  powerup_.ramp_in = powerup_.ramp_in_started = false;
  powerup_.under_way = p_.powerup_V > 0.0 && u_V < p_.low_V;
  powerup_.settled_s = 0.0;
  band_pass_.reset();
}

void TrackingController::emergency_stop() noexcept {
  stopped_ = true;
  edge_ = false;
  u_ = u_cmd_ = 0.0;
}

void TrackingController::start_edge(double x, bool forward) noexcept {
  const Direction d = forward ? Direction::kForward : Direction::kBackward;
  const double low = sprint_ ? p_.sprint_low_V : p_.low_V;
  op_.amplitude_V = p_.high_V - low;
  op_.frequency_Hz = flyback_frequency_Hz(ref_.v_m_s, op_.amplitude_V, d);
  op_.direction = d;
  edge_ = true;
  // A backward edge spans the sawtooth's amplitude from the ramp's floor: from the range's bottom
  // that is high_V; from below it (the amplifier at 0 V after power-up) it stays as wide as every
  // other edge, and the ramp keeps using the voltages below low_V (a full 0 -> high_V edge slips
  // further and rings harder: a 200 um/s backward move from power-up peaked at 650 nm of error
  // with it, 624 nm with this one).
  const double target = forward ? low : std::min(p_.high_V, floor_V_ + op_.amplitude_V);
  if (forward) floor_V_ = low;
  plan_edge(target, p_.unload_V * op_.amplitude_V / (p_.high_V - p_.low_V), p_.edge_split_s);
  backslip_.edge_at(x, forward);
  ++edges_;
}

void TrackingController::plan_edge(double target_V, double unload_V, double split_s) noexcept {
  const double back = target_V < u_ ? 1.0 : -1.0;  // the unloading turns against the edge
  leg_ = leg_count_ = 0;
  const auto to = [this](double v) { legs_[static_cast<std::size_t>(leg_count_++)] = {v, 0.0}; };
  if (split_s <= 0.0) {
    to(target_V);
    if (unload_V > 0.0) to(target_V + back * unload_V);
    return;
  }
  // Two halves, each an edge and its unloading at half the voltages; the second starts split_s
  // after the first (at once if the first takes longer).
  const double half = 0.5 * (target_V - u_), middle = u_ + half;
  to(middle);
  if (unload_V > 0.0) to(middle + back * 0.5 * unload_V);
  const double first_s = (std::abs(half) + 0.5 * unload_V) / slew_;
  if (split_s > first_s) {
    const double held = legs_[static_cast<std::size_t>(leg_count_ - 1)].to_V;
    legs_[static_cast<std::size_t>(leg_count_++)] = {held, split_s - first_s};
  }
  to(target_V + back * 0.5 * unload_V);
  if (unload_V > 0.0) to(target_V + back * unload_V);
}

void TrackingController::start_ramp_in(double x) noexcept {
  // One backward-type edge (the voltage rises at the slew limit, the slider slips and stays but
  // for a small drag) from the power-up voltage to powerup_V + powerup_unload_V, then the
  // unloading back to powerup_V. The slider's displacement is measured and caught up by the ramp
  // while the reference rests. It is not a step of the move: edges() does not count it, nor does
  // its outcome refine the backslip estimates.
  op_.amplitude_V = p_.powerup_V + p_.powerup_unload_V - u_;
  op_.direction = Direction::kBackward;
  edge_ = true;
  plan_edge(p_.powerup_V + p_.powerup_unload_V, p_.powerup_unload_V, 0.0);
  backslip_.edge_at(x, false, 0.0);
  powerup_.ramp_in = powerup_.ramp_in_started = true;
}

void TrackingController::anchor_after_edge() noexcept {
  // The slider kept its place but for the backslip: anchor the ramp there. The error the plan
  // now has (the reference moved on, the lead, the backslip) is caught up smoothly.
  const double x_after = backslip_.landing_m();
  y_anchor_ = pe_displacement_m(u_);
  r_anchor_ = ref_.x_m;
  catch_up_.restart(ref_.x_m - x_after);
  integ_ = 0.0;  // the anchor restarts the plan: the ramp's correction starts again from zero
  since_edge_s_ = 0.0;
  pending_anchor_ = false;
  backslip_.await_outcome();
}

void TrackingController::update(double x) noexcept {
  if (stopped_) return;
  if (!have_x_) {
    x_filt_ = x;
    have_x_ = true;
  }
  x_filt_ += dt_c_ / (p_.filter_s + dt_c_) * (x - x_filt_);
  // The damping's band-pass runs on every sample (also during edges: it sees the slip).
  const double bp = band_pass_.step(x);
  in_position_ = ref_.v_m_s == 0.0 && std::abs(ref_.x_m - x_filt_) < p_.in_position_m;
  if (powerup_.under_way) {
    if (!powerup_.ramp_in_started) {
      start_ramp_in(x);
      return;
    }
    // Ready once the ramp-in and any edge the hold took after it to catch the drag up are
    // powerup_settle_s past, and the filtered error is small.
    powerup_.settled_s = edge_ || pending_anchor_ ? 0.0 : powerup_.settled_s + dt_c_;
    if (powerup_.settled_s >= p_.powerup_settle_s && std::abs(ref_.x_m - x_filt_) < p_.powerup_ready_m) {
      powerup_.under_way = false;
    }
  }
  if (edge_) return;  // the edge runs in next_drive()
  if (pending_anchor_) {
    anchor_after_edge();
    if (powerup_.ramp_in) floor_V_ = p_.low_V;  // the drive is in range now
  }
  since_edge_s_ += dt_c_;
  catch_up_.update(since_edge_s_ / p_.catchup_s);
  const double e = ref_.x_m - x;
  const double e_plan = catch_up_.remaining();  // the error the catch-up still expects
  if (backslip_.awaiting_outcome() && since_edge_s_ >= p_.settle_s) {
    // The edge's outcome: the anchor was off by `miss` (measured). Refine the backslip estimate
    // and catch the miss up too (a second raised cosine from here).
    const double miss = e - e_plan;
    backslip_.settle(miss, p_.backslip_gain, !powerup_.ramp_in);
    powerup_.ramp_in = false;
    catch_up_.add(miss);
    since_edge_s_ = 0.0;
  }
  // Sprint (the wider range) while the reference is fast or the axis has fallen behind it (at
  // rest: is far from it); the ramp may then run down to the sprint range's bottom. The velocity
  // trigger looks sprint_horizon_s ahead while the reference speeds up.
  const double lag = ref_.v_m_s > 0.0 ? e : (ref_.v_m_s < 0.0 ? -e : std::abs(e));
  const double speeding_up =
      ref_.a_m_s2 * ref_.v_m_s > 0.0 ? std::abs(ref_.a_m_s2) * p_.sprint_horizon_s : 0.0;
  if (std::abs(ref_.v_m_s) + speeding_up > p_.sprint_velocity_m_s || lag > p_.sprint_lag_m) {
    sprint_ = true;
    floor_V_ = std::min(floor_V_, p_.sprint_low_V);
  } else if (lag < 0.5 * p_.sprint_lag_m) {
    sprint_ = false;
  }
  // Lead before an edge: the ramp runs ahead of (forward) or behind (backward) the reference by a
  // growing fraction of the backslip, so the edge's jump is split around zero.
  const double y_base = y_anchor_ + (ref_.x_m - r_anchor_) + catch_up_.now() + integ_;
  const double top = pe_displacement_m(p_.high_V - p_.guard_V);
  const double bottom = pe_displacement_m(floor_V_ + p_.guard_V);
  // Where the lead stands is judged on the plan (anchor, reference, catch-up) when lead_on_plan
  // is set, not on y_base with its feedback (integral): in the lead window the lead grows by
  // (b + lead_m) / lead_window_m ~ 4 m per metre of y, which multiplies the feedback's own swing
  // by ~5 there and rings the loop at ~400 Hz (+-280 nm at 23 um/s backward).
  const double y_lead = p_.lead_on_plan ? y_anchor_ + (ref_.x_m - r_anchor_) + catch_up_.now() : y_base;
  double lead = 0.0;
  if (ref_.v_m_s > 0.0) {
    lead = (p_.lead_fraction * backslip_.of(true) + p_.lead_m) *
           std::clamp(1.0 - (top - y_lead) / p_.lead_window_m, 0.0, 1.0);
  } else if (ref_.v_m_s < 0.0) {
    lead = -(p_.lead_fraction * backslip_.of(false) + p_.lead_m) *
           std::clamp(1.0 - (y_lead - bottom) / p_.lead_window_m, 0.0, 1.0);
  }
  // Resonant damping of the contact's 1.64 kHz mode (see TrackingParams::damp_gain).
  const double damp =
      p_.damp_gain * ((1.0 - p_.damp_lag_ticks) * bp + p_.damp_lag_ticks * band_pass_.previous());
  // The residual: the measured error minus the error the plan expects (catch-up still to go, lead).
  const double e_res = e - catch_up_.remaining() + lead;
  const double y_des = y_base + lead + p_.kp * e_res + damp;
  // An edge when the ramp runs out of range in the direction the reference moves, or, at rest,
  // when the wanted position lies beyond the range by more than the edge margin; never against
  // the reference's motion; and only once the drive has used its range (within edge_ready_V of
  // its end): an axis that fell behind would otherwise take its edges straight after the
  // unloading, each advancing by a few volts' worth, and never catch up.
  const double v = ref_.v_m_s;
  if (y_des > top && v >= 0.0 && (v > 0.0 || y_des > pe_displacement_m(p_.high_V) + p_.edge_margin_m) &&
      u_ >= p_.high_V - p_.guard_V - p_.edge_ready_V) {
    start_edge(x, true);
    return;
  }
  if (y_des < bottom && v <= 0.0 && (v < 0.0 || y_des < pe_displacement_m(floor_V_) - p_.edge_margin_m) &&
      u_ <= floor_V_ + p_.guard_V + p_.edge_ready_V) {
    start_edge(x, false);
    return;
  }
  // Integral on the residual, frozen while the slip rings and when the ramp is saturated the way
  // the residual pushes (anti-windup).
  const bool sat_hi = y_des >= pe_displacement_m(p_.high_V) && e_res > 0.0;
  const bool sat_lo = y_des <= pe_displacement_m(floor_V_) && e_res < 0.0;
  if (!backslip_.awaiting_outcome() && !sat_hi && !sat_lo) integ_ += p_.ki_1_s * dt_c_ * e_res;
  u_prev_cmd_ = u_cmd_;
  u_cmd_ = inverse_V(y_des);
}

stickslip::DriveSegment TrackingController::next_drive(double dt_s) noexcept {
  stickslip::DriveSegment seg;
  if (stopped_) {
    u_ = 0.0;
    seg.end_V = 0.0;
    return seg;
  }
  if (edge_) {
    // The edge's legs (the edge, its unloading reversal, a split edge's hold) at the slew limit;
    // a corner wherever a leg ends.
    double left = dt_s;
    while (edge_ && left > 0.0) {
      EdgeLeg& leg = legs_[static_cast<std::size_t>(leg_)];
      const bool hold = leg.hold_s > 0.0;
      const double need = hold ? leg.hold_s : std::abs(leg.to_V - u_) / slew_;
      if (need > left) {
        if (hold)
          leg.hold_s -= left;
        else
          u_ += std::copysign(slew_ * left, leg.to_V - u_);
        break;
      }
      left -= need;
      u_ = leg.to_V;
      if (left > dt_s * 1e-9 && seg.corners < stickslip::DriveSegment::kMaxCorners) {
        seg.u_V[static_cast<std::size_t>(seg.corners)] = u_;
        seg.at[static_cast<std::size_t>(seg.corners)] = (dt_s - left) / dt_s;
        ++seg.corners;
      }
      if (++leg_ == leg_count_) {
        edge_ = false;
        pending_anchor_ = true;
        u_cmd_ = u_prev_cmd_ = u_;
      }
    }
    if (!edge_ && left > 0.0 && seg.corners > 0 && seg.at[static_cast<std::size_t>(seg.corners - 1)] >= 1.0) {
      --seg.corners;
    }
  } else {
    // The ramp: linear from the last command to this one over the control period. Once it rises
    // into the range from below (power-up), the range's bottom is its floor.
    const double du = std::max(std::abs(u_cmd_ - u_prev_cmd_) / dt_c_, 1.0) * dt_s;
    const double before = u_;
    u_ += std::clamp(u_cmd_ - u_, -du, du);
    if (!sprint_ && before < p_.low_V && u_ >= p_.low_V) floor_V_ = p_.low_V;
  }
  for (int j = 0; j < seg.corners; ++j) stickslip::pi_update(pi_, obs_, seg.u_V[static_cast<std::size_t>(j)]);
  u_ = std::clamp(u_, floor_V_, p_.high_V);
  stickslip::pi_update(pi_, obs_, u_);
  seg.end_V = u_;
  return seg;
}

}  // namespace mc::motion
