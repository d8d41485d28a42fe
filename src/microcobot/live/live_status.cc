#include "microcobot/live/live_status.h"

namespace mc::live {

void LoopReadings::publish(platform::Platform& p, double t_live_s) noexcept {
  constexpr auto relaxed = std::memory_order_relaxed;
  t_s_.store(t_live_s, relaxed);
  estopped_.store(p.faulted(), relaxed);
  for (int i = 0; i < 3; ++i)
    lifecycle_[static_cast<std::size_t>(i)].store(static_cast<int>(p.axis(i).state()), relaxed);
  lifecycle_[3].store(static_cast<int>(p.gripper().state()), relaxed);
  lifecycle_[4].store(static_cast<int>(p.haptic().state()), relaxed);
  lifecycle_[5].store(static_cast<int>(p.tweezers().state()), relaxed);
  rotary_lifecycle_.store(p.rotary_axis() ? static_cast<int>(p.rotary_axis()->state()) : -1, relaxed);
  overruns_.store(p.loop().overruns(), relaxed);
  if (const devices::FocusDrive* focus = p.focus()) {
    focus_z_m_.store(focus->z_m(), relaxed);
    focus_target_m_.store(focus->target_z_m(), relaxed);
    objective_.store(focus->objective(), relaxed);
    camera_dropped_.store(p.camera()->dropped(), relaxed);
  }
  ticks_.store(p.loop().ticks(), relaxed);
  if (p.gripper().has_align_drives()) {
    const platform::TipLevellingStatus& l = p.tip_levelling();
    levelling_phase_.store(static_cast<int>(l.phase), relaxed);
    levelling_passes_.store(l.passes, relaxed);
    levelling_failure_.store(l.failure, relaxed);
    levelling_before_m_.store(l.misalignment_before_m, relaxed);
    levelling_misalignment_m_.store(p.tip_misalignment_m(), relaxed);  // now, whatever the state
    levelling_peak_N_.store(l.peak_contact_N, relaxed);
    levelling_state_.store(static_cast<int>(l.state), relaxed);
  } else {
    levelling_state_.store(-1, relaxed);
  }
}

void LoopReadings::fill(LiveStatus& s) const noexcept {
  constexpr auto relaxed = std::memory_order_relaxed;
  s.t_s = t_s_.load(relaxed);
  s.estopped = estopped_.load(relaxed);
  for (std::size_t i = 0; i < 6; ++i)
    s.lifecycle[i] = static_cast<devices::Lifecycle>(lifecycle_[i].load(relaxed));
  const int rotary = rotary_lifecycle_.load(relaxed);
  s.has_rotary = rotary >= 0;
  if (s.has_rotary) s.rotary_lifecycle = static_cast<devices::Lifecycle>(rotary);
  s.overruns = overruns_.load(relaxed);
  s.ticks = ticks_.load(relaxed);
  s.camera_dropped = camera_dropped_.load(relaxed);
  s.focus_z_m = focus_z_m_.load(relaxed);
  s.focus_target_m = focus_target_m_.load(relaxed);
  s.objective = objective_.load(relaxed);
  const int levelling = levelling_state_.load(relaxed);
  if (levelling >= 0) {
    platform::TipLevellingStatus l;
    l.state = static_cast<platform::TipLevellingStatus::State>(levelling);
    l.phase = static_cast<microworld::AlignmentPhase>(levelling_phase_.load(relaxed));
    l.passes = levelling_passes_.load(relaxed);
    l.failure = levelling_failure_.load(relaxed);
    l.misalignment_before_m = levelling_before_m_.load(relaxed);
    l.misalignment_m = levelling_misalignment_m_.load(relaxed);
    l.peak_contact_N = levelling_peak_N_.load(relaxed);
    s.levelling = l;
  }
}

}  // namespace mc::live
