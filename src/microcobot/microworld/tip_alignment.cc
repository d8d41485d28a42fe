#include "microcobot/microworld/tip_alignment.h"

#include <algorithm>
#include <cmath>

namespace mc::microworld {

void TipAlignmentParams::validate() const {
  require(std::isfinite(approach_m_s) && approach_m_s > 0.0 && approach_m_s <= 1e-3, "alignment.approach_m_s",
          "must be within (0, 1 mm/s]", approach_m_s);
  require_positive(contact_threshold_N, "alignment.contact_threshold_N");
  require(std::isfinite(max_contact_N) && max_contact_N > contact_threshold_N, "alignment.max_contact_N",
          "must be > contact_threshold_N", max_contact_N);
  require_positive(level_V_s, "alignment.level_V_s");
  require_positive(lift_m, "alignment.lift_m");
  require(std::isfinite(settle_s) && settle_s >= 0.0 && settle_s <= 600.0, "alignment.settle_s",
          "must be within [0, 600] s", settle_s);
  require_positive(tolerance_m, "alignment.tolerance_m");
  require_positive(max_travel_m, "alignment.max_travel_m");
  require(max_passes >= 1 && max_passes <= 20, "alignment.max_passes", "must be within [1, 20]", max_passes);
}

const char* to_string(AlignmentPhase p) noexcept {
  switch (p) {
    case AlignmentPhase::kIdle:
      return "idle";
    case AlignmentPhase::kApproach:
      return "approach";
    case AlignmentPhase::kLevel:
      return "level";
    case AlignmentPhase::kLift:
      return "lift";
    case AlignmentPhase::kSettle:
      return "settle";
    case AlignmentPhase::kDone:
      return "done";
    case AlignmentPhase::kFailed:
      return "failed";
  }
  return "?";
}

TipAlignment::TipAlignment(const TipAlignmentParams& p, double align_limit_V)
    : p_(p), align_limit_V_(align_limit_V) {
  p_.validate();
  require_positive(align_limit_V, "alignment.align_limit_V");
}

void TipAlignment::start(const BenderDrives& drives) noexcept {
  drives_ = drives;
  phase_ = AlignmentPhase::kApproach;
  passes_ = 1;
  first_ = -1;
  travelled_m_ = phase_s_ = 0.0;
  level_ = false;
  failure_ = "";
}

AlignmentCommand TipAlignment::fail(const char* why) noexcept {
  phase_ = AlignmentPhase::kFailed;
  failure_ = why;
  return hold();
}

AlignmentCommand TipAlignment::tick(const TipReading& tips, double dt_s) noexcept {
  if (finished() || phase_ == AlignmentPhase::kIdle) return hold();
  if (tips.contact_N[0] > p_.max_contact_N || tips.contact_N[1] > p_.max_contact_N)
    return fail("a tip pressed beyond alignment.max_contact_N");
  phase_s_ += dt_s;
  const bool touch[2] = {tips.contact_N[0] >= p_.contact_threshold_N,
                         tips.contact_N[1] >= p_.contact_threshold_N};
  const auto next = [&](AlignmentPhase ph) {
    phase_ = ph;
    phase_s_ = 0.0;
    travelled_m_ = 0.0;
  };
  switch (phase_) {
    case AlignmentPhase::kApproach: {
      if (touch[0] && touch[1]) {
        // Both down within tolerance_m of descent after the first (or in the same tick): level.
        level_ = true;
        next(AlignmentPhase::kLift);
        return hold();
      }
      if (first_ < 0 && (touch[0] || touch[1])) {
        first_ = touch[0] ? 0 : 1;
        travelled_m_ = 0.0;
      }
      if (first_ >= 0 && travelled_m_ >= p_.tolerance_m) {
        next(AlignmentPhase::kLevel);  // the other one is higher: bring it down
        return hold();
      }
      if (first_ < 0 && travelled_m_ >= p_.max_travel_m)
        return fail("no tip touched within alignment.max_travel_m");
      travelled_m_ += p_.approach_m_s * dt_s;
      return {-p_.approach_m_s, drives_};
    }
    case AlignmentPhase::kLevel: {
      const auto other = static_cast<std::size_t>(1 - first_);
      if (touch[other]) {
        next(AlignmentPhase::kLift);
        return hold();
      }
      double& u = drives_.align_V[other];
      if (u <= -align_limit_V_) return fail("an align drive reached its limit before its tip touched");
      u = std::max(-align_limit_V_, u - p_.level_V_s * dt_s);
      return hold();
    }
    case AlignmentPhase::kLift:
      if (travelled_m_ >= p_.lift_m) {
        first_ = -1;
        if (level_) {
          next(AlignmentPhase::kDone);
        } else if (passes_ >= p_.max_passes) {
          return fail("the tips were not level after alignment.max_passes passes");
        } else {
          next(AlignmentPhase::kSettle);
        }
        return hold();
      }
      travelled_m_ += p_.approach_m_s * dt_s;
      return {p_.approach_m_s, drives_};
    case AlignmentPhase::kSettle:
      if (phase_s_ >= p_.settle_s) {
        ++passes_;
        next(AlignmentPhase::kApproach);
      }
      return hold();
    default:
      return hold();
  }
}

AlignmentRun run_tip_alignment(const BenderFingersParams& fingers, BenderFingersState state,
                               const BenderDrives& drives, const TipAlignmentParams& params, double height_m,
                               double after_s, double dt_s) {
  fingers.validate();
  TipAlignment procedure(params, fingers.align.max_voltage_V);
  AlignmentRun run;
  run.misalignment_before_m = misalignment_m(fingers, state);
  procedure.start(drives);
  double height = height_m;
  BenderDrives applied = drives;
  // The longest the procedure may take: each pass's descent, levelling sweep, lift and settle.
  const double pass_s = (params.max_travel_m + params.lift_m) / params.approach_m_s +
                        2.0 * fingers.align.max_voltage_V / params.level_V_s + params.settle_s;
  const double budget_s = params.max_passes * pass_s + 10.0;
  double t = 0.0;
  while (!procedure.finished() && t < budget_s) {
    const TipReading tips = read_tips(fingers, state, -height);
    run.peak_contact_N = std::max({run.peak_contact_N, tips.contact_N[0], tips.contact_N[1]});
    const AlignmentCommand c = procedure.tick(tips, dt_s);
    height += c.z_velocity_m_s * dt_s;
    applied = c.drives;
    step_fingers(fingers, state, applied, dt_s);
    t += dt_s;
  }
  run.duration_s = t;
  run.passes = procedure.passes();
  run.done = procedure.phase() == AlignmentPhase::kDone;
  run.failure =
      procedure.finished() ? procedure.failure() : "the procedure did not finish in its time budget";
  run.misalignment_after_m = misalignment_m(fingers, state);
  for (double u = 0.0; u < after_s; u += 0.01) step_fingers(fingers, state, applied, 0.01);
  run.misalignment_later_m = misalignment_m(fingers, state);
  return run;
}

}  // namespace mc::microworld
