// The PiezoGripper's tips levelled by touch on the slave (thesis §1.1.4: "the vertical motion is
// used to align the fingertips"; microworld/tip_alignment.h): the procedure ticked on the loop with
// the gripper's tip contacts, its Z speed integrated into the stage's target and its drives sent to
// the gripper's align benders, under the rule of the pose moves (the deadman of the input that
// drives the coupling) and the platform's contact limit.
#include <algorithm>
#include <cmath>

#include "microcobot/platform/platform.h"

namespace mc::platform {

const char* to_string(TipLevellingStatus::State s) noexcept {
  switch (s) {
    case TipLevellingStatus::State::kIdle:
      return "idle";
    case TipLevellingStatus::State::kRunning:
      return "running";
    case TipLevellingStatus::State::kDone:
      return "done";
    case TipLevellingStatus::State::kFailed:
      return "failed";
  }
  return "?";
}

double Platform::tip_misalignment_m() const noexcept {
  return sim_.gripper != nullptr ? sim_.gripper->tip_misalignment_m() : std::nan("");
}

bool Platform::start_tip_levelling() noexcept {
  if (tip_levelling_running()) return false;  // the one under way goes on
  const char* refusal = nullptr;
  if (alignment_ == nullptr) {
    refusal = "refused: the gripper has no align drives";
  } else if (!pose_move_allowed()) {
    refusal = "refused: the console must drive with its deadman held";
  } else {
    for (int i = 0; i < 4; ++i)
      if (open_loop_running(i)) refusal = "refused: an open-loop run is under way";
  }
  if (refusal != nullptr) {
    refuse_tip_levelling(refusal);
    return false;
  }
  levelling_ = TipLevellingStatus{};
  levelling_.misalignment_before_m = levelling_.misalignment_m = tip_misalignment_m();
  microworld::BenderDrives drives;
  drives.align_V = devices_.gripper->align_V();
  alignment_->start(drives);
  levelling_target_m_ = {devices_.axes[0]->position_m(), devices_.axes[1]->position_m(),
                         devices_.axes[2]->position_m()};
  levelling_velocity_m_s_ = 0.0;
  const auto tips = devices_.gripper->tip_contact_N();
  levelling_press_N_ = std::max(tips[0], tips[1]);
  levelling_press_rate_N_s_ = 0.0;
  levelling_.state = TipLevellingStatus::State::kRunning;
  levelling_.phase = alignment_->phase();
  levelling_.passes = alignment_->passes();
  return true;
}

void Platform::refuse_tip_levelling(const char* why) noexcept {
  if (tip_levelling_running()) return;
  levelling_ = TipLevellingStatus{};
  levelling_.misalignment_before_m = levelling_.misalignment_m = tip_misalignment_m();
  levelling_.state = TipLevellingStatus::State::kFailed;
  levelling_.failure = why;
}

void Platform::stop_tip_levelling() noexcept {
  if (tip_levelling_running()) end_levelling(TipLevellingStatus::State::kFailed, "stopped");
}

void Platform::end_levelling(TipLevellingStatus::State state, const char* why) noexcept {
  levelling_.state = state;
  levelling_.failure = why;
  levelling_.phase = alignment_->phase();
  levelling_.passes = alignment_->passes();
  levelling_.misalignment_m = tip_misalignment_m();
  levelling_velocity_m_s_ = 0.0;
  // Every automatic sequence ends holding: the targets re-taken where the axes are, the align
  // drives left where the procedure put them.
  hold();
}

void Platform::levelling_task(double dt_s) noexcept {
  if (!tip_levelling_running()) return;
  using State = TipLevellingStatus::State;
  if (faulted_) return end_levelling(State::kFailed, "a fault or the e-stop");
  if (!pose_move_allowed())
    return end_levelling(State::kFailed, "the deadman was released (or the console lost control)");
  const devices::Vec3 f = devices_.gripper->contact_force_N();
  if (std::hypot(f.x, f.y, f.z) > world_.params().contact_force_limit_N)
    return end_levelling(State::kFailed, "the contact force passed contact_force_limit_N");
  microworld::TipReading tips;
  tips.contact_N = devices_.gripper->tip_contact_N();
  const double press = std::max(tips.contact_N[0], tips.contact_N[1]);
  levelling_.peak_contact_N = std::max(levelling_.peak_contact_N, press);
  // The stage does not stop within a tick: stopped where the press would pass the limit within its
  // stopping time at the rate it rises (smoothed over kLevellingRateTau_s: the stick-slip steps
  // raise it in jumps), it stays under the limit instead of being caught above it.
  const double rate = dt_s > 0.0 ? (press - levelling_press_N_) / dt_s : 0.0;
  levelling_press_N_ = press;
  levelling_press_rate_N_s_ += (rate - levelling_press_rate_N_s_) * std::min(1.0, dt_s / kLevellingRateTau_s);
  if (press + std::max(0.0, levelling_press_rate_N_s_) * kLevellingStop_s >= config_.alignment.max_contact_N)
    return end_levelling(State::kFailed, "a tip's press would pass alignment.max_contact_N");
  const microworld::AlignmentCommand c = alignment_->tick(tips, dt_s);
  devices_.gripper->command_align_V(c.drives.align_V);
  levelling_velocity_m_s_ = c.z_velocity_m_s;
  levelling_target_m_.z() += c.z_velocity_m_s * dt_s;
  levelling_.phase = alignment_->phase();
  levelling_.passes = alignment_->passes();
  levelling_.misalignment_m = tip_misalignment_m();
  if (alignment_->phase() == microworld::AlignmentPhase::kDone) return end_levelling(State::kDone, "");
  if (alignment_->finished()) return end_levelling(State::kFailed, alignment_->failure());
}

void Platform::levelling_targets(std::array<double, StageController::kMaxAxes>& target,
                                 std::array<double, StageController::kMaxAxes>& velocity) const noexcept {
  if (!tip_levelling_running()) return;
  for (std::size_t i = 0; i < 3; ++i) {
    target[i] = levelling_target_m_[static_cast<Eigen::Index>(i)];
    velocity[i] = i == 2 ? levelling_velocity_m_s_ : 0.0;
  }
}

}  // namespace mc::platform
