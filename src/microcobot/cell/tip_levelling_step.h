#pragma once
/// @file
/// The cell's first step on a PiezoGripper (thesis §1.1.4: "the vertical motion is used to align
/// the fingertips"): before the pick, the tips are levelled by touch on a clear patch of the
/// substrate, as the console's action levels them (Platform::start_tip_levelling,
/// microworld/tip_alignment.h). Tips at different heights hold a part with the faces' overlap
/// only, and tilt it (microworld/bender_fingers.h).
///
///   over    to the clear patch, at the height the cycle starts from
///   down    to height_m over the substrate there (the procedure looks for the touch from there)
///   level   the platform's procedure, under this input's deadman; it ends holding
///   back    up and back where the cycle started, for the task's approach
///
/// Each tick it drives the platform through its console input (active, fresh, deadman held), so
/// the platform's rules apply to it as to any input; on the loop, real-time safe. A procedure the
/// platform refuses or that fails ends the step failed, every axis holding.

#include <string>

#include <Eigen/Dense>

#include "microcobot/cell/assembly_task.h"
#include "microcobot/platform/platform.h"
#include "microcobot/teleop/teleoperation.h"

namespace mc::cell {

struct TipLevellingStepParams {
  /// "on": the tips levelled at each cycle's start (about 15 s: the procedure's creep check waits
  /// 5 s); "off" (the default: a gripper whose tips were levelled once, as the cell's figures are).
  std::string mode = "off";
  /// The clear patch: between the default tray (x up to -0.25 mm and its pins' half-sides) and the
  /// default plate (from +0.75 mm), away from both by more than the open fingers' reach.
  double x_m = 0.25e-3;
  double y_m = 0.0;
  double height_m = 60e-6;           ///< the tips over the substrate when the procedure starts
  double travel_speed_m_s = 500e-6;  ///< the task's travel speed
  double z_speed_m_s = 200e-6;       ///< and its vertical speed

  template <class V>
  void visit(V& v) {
    v("mode", mode);
    v("x_m", x_m);
    v("y_m", y_m);
    v("height_m", height_m);
    v("travel_speed_m_s", travel_speed_m_s);
    v("z_speed_m_s", z_speed_m_s);
  }
  /// Throws mc::InvalidParams naming the field (level_tips.*).
  void validate() const;
};

class TipLevellingStep {
 public:
  enum class Phase { kOver, kDown, kLevel, kBack, kDone, kFailed };

  /// `open_m`: the fingers' opening meanwhile (open, as the task's approach has them). Throws
  /// mc::InvalidParams.
  TipLevellingStep(const TipLevellingStepParams& params, double open_m);

  /// One tick on the loop: the platform's console input for this tick, the procedure started and
  /// followed. Real-time safe.
  void tick(platform::Platform& p, const TaskSensors& s) noexcept;

  Phase phase() const noexcept { return phase_; }
  bool finished() const noexcept { return phase_ == Phase::kDone || phase_ == Phase::kFailed; }
  const char* failure() const noexcept { return failure_; }

 private:
  /// Heads for `goal` at `speed`: true once the tool is within a micrometre of it.
  bool head_for(const Eigen::Vector3d& goal, double speed, const TaskSensors& s) noexcept;
  void fail(platform::Platform& p, const char* why) noexcept;

  TipLevellingStepParams p_;
  Phase phase_ = Phase::kOver;
  bool started_ = false;
  Eigen::Vector3d start_ = Eigen::Vector3d::Zero();
  const char* failure_ = "";
  teleop::ConsoleInput in_;
};

}  // namespace mc::cell
