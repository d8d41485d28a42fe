#pragma once
/// @file
/// Levelling the PiezoGripper's tips by touching the substrate (bender_fingers.h): the gripper
/// comes down until a tip touches, the other tip's align bender lowers it until it touches too
/// (both now stand on the same plane), the gripper lifts, and after the moved bender's creep has
/// had time to show, the touch is checked again (and levelled again where it moved). Ticked at the
/// loop's rate; it allocates nothing.
///
/// A touch is a tip's vertical contact force reaching contact_threshold_N (the force by vision or
/// a force sensor reads it); both tips then press to within a few nanometres of the same depth,
/// threshold / stiffness. What a pass leaves is the creep of the bender it moved: a step of
/// dz on a bender creeping by c per decade of time drifts by about c dz per decade after it, so
/// the check after settle_s sees (and takes out) most of the creep of a 20 um correction.
///
///   approach  the gripper down at approach_m_s until a tip touches (the other one too, within
///             tolerance_m more of descent: then the tips are level and the pass ends)
///   level     the other tip's align drive ramped down at level_V_s until it touches
///   lift      the gripper up by lift_m
///   settle    settle_s waited (the creep of the bender just moved)
///   ...       approach again, up to max_passes; done when a pass finds the tips level
///
/// Safe on faults: a contact force above max_contact_N, a tip that does not touch within its
/// travel, or an align drive at its limit stops the gripper (z velocity 0) and fails with the
/// reason; the drives hold where they are.

#include <cstdint>

#include "microcobot/core/params.h"
#include "microcobot/microworld/bender_fingers.h"

namespace mc::microworld {

struct TipAlignmentParams {
  double approach_m_s = 20e-6;         ///< the gripper's descent while looking for a touch
  double contact_threshold_N = 20e-6;  ///< a touch (0.4 um of press at 50 N/m)
  double max_contact_N = 500e-6;       ///< beyond this the procedure stops (a fault)
  double level_V_s = 20.0;             ///< the align drive's ramp while levelling
  double lift_m = 30e-6;               ///< the lift between passes and at the end
  double settle_s = 5.0;               ///< the wait before the check pass (the creep shows)
  double tolerance_m = 0.5e-6;         ///< tips level when the second touches within this
  double max_travel_m = 200e-6;        ///< the longest descent looking for a touch
  int max_passes = 4;  ///< passes at most (approach, level, lift, settle): the last must find the tips level

  template <class V>
  void visit(V& v) {
    v("approach_m_s", approach_m_s);
    v("contact_threshold_N", contact_threshold_N);
    v("max_contact_N", max_contact_N);
    v("level_V_s", level_V_s);
    v("lift_m", lift_m);
    v("settle_s", settle_s);
    v("tolerance_m", tolerance_m);
    v("max_travel_m", max_travel_m);
    v("max_passes", max_passes);
  }
  /// Throws mc::InvalidParams naming the field (alignment.*).
  void validate() const;
};

enum class AlignmentPhase : std::uint8_t { kIdle, kApproach, kLevel, kLift, kSettle, kDone, kFailed };
const char* to_string(AlignmentPhase p) noexcept;

/// What the procedure asks each tick: the gripper's vertical speed (the Z stage) and the four
/// drives (the grasp drives as they were at start()).
struct AlignmentCommand {
  double z_velocity_m_s = 0.0;
  BenderDrives drives;
};

class TipAlignment {
 public:
  /// Throws mc::InvalidParams.
  explicit TipAlignment(const TipAlignmentParams& p = {}, double align_limit_V = 150.0);

  /// Starts from the drives applied now, the tips off the substrate.
  void start(const BenderDrives& drives) noexcept;
  /// One tick of `dt_s` with the tips' reading: the command for this tick. Never allocates.
  AlignmentCommand tick(const TipReading& tips, double dt_s) noexcept;

  AlignmentPhase phase() const noexcept { return phase_; }
  bool finished() const noexcept {
    return phase_ == AlignmentPhase::kDone || phase_ == AlignmentPhase::kFailed;
  }
  int passes() const noexcept { return passes_; }
  /// Why it failed (a static string; empty otherwise).
  const char* failure() const noexcept { return failure_; }

 private:
  AlignmentCommand hold() const noexcept { return {0.0, drives_}; }
  AlignmentCommand fail(const char* why) noexcept;

  TipAlignmentParams p_;
  double align_limit_V_;
  AlignmentPhase phase_ = AlignmentPhase::kIdle;
  BenderDrives drives_;
  int passes_ = 0;
  int first_ = -1;            ///< the tip that touched first in this pass
  double travelled_m_ = 0.0;  ///< descent since the pass began (approach) or since the first touch
  double phase_s_ = 0.0;      ///< time in the phase
  bool level_ = false;        ///< a pass found the tips level: lift, then done
  const char* failure_ = "";
};

/// The procedure run on the simulated fingers under an ideal Z stage (it follows the commanded
/// speed), the substrate `height_m` below the tips' rest plane at the start, at `dt_s` a tick;
/// then `after_s` more at rest, lifted (the creep goes on). What it leaves.
struct AlignmentRun {
  double misalignment_before_m = 0.0;
  double misalignment_after_m = 0.0;  ///< when the procedure finished
  double misalignment_later_m = 0.0;  ///< after_s later
  double peak_contact_N = 0.0;
  double duration_s = 0.0;
  int passes = 0;
  bool done = false;
  const char* failure = "";
};
AlignmentRun run_tip_alignment(const BenderFingersParams& fingers, BenderFingersState state,
                               const BenderDrives& drives, const TipAlignmentParams& params, double height_m,
                               double after_s = 60.0, double dt_s = 1e-3);

}  // namespace mc::microworld
