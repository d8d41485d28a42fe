#include "microcobot/platform/stage_controller.h"

#include <cmath>

#include "microcobot/core/error.h"

namespace mc::platform {

StageController::StageController(const motion::PositionControlParams& params,
                                 const stickslip::StickSlipParams& model, const motion::StepMap& map,
                                 int samples_per_tick, double sample_period_s,
                                 const motion::TrackingParams* tracking, int axes)
    : axes_(axes), sample_period_s_(sample_period_s) {
  require(axes == 3 || axes == kMaxAxes, "axes", "must be 3 (XYZ) or 4 (XYZ and the rotary axis)", axes);
  require(samples_per_tick >= 1, "samples_per_tick", "must be at least 1", samples_per_tick);
  require_positive(sample_period_s, "sample_period_s");
  tick_s_ = static_cast<double>(samples_per_tick) * sample_period_s;
  fast_ = tracking != nullptr && std::abs(tracking->control_rate_Hz * tick_s_ - 1.0) < 1e-9;
  for (std::size_t i = 0; i < static_cast<std::size_t>(axes_); ++i) {
    if (tracking) {
      track_[i] = std::make_unique<motion::TrackingController>(*tracking, model, map);
    } else {
      ctrl_[i] = std::make_unique<motion::PositionController>(params, model, map);
    }
    samples_[i].assign(static_cast<std::size_t>(samples_per_tick), stickslip::DriveSegment{});
  }
}

void StageController::update(const Eigen::Vector3d& target_m, const Eigen::Vector3d& velocity_m_s,
                             const std::array<double, 3>& measured_m) noexcept {
  std::array<double, kMaxAxes> t{}, v{}, m{};
  for (std::size_t i = 0; i < 3; ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    t[i] = target_m[k], v[i] = velocity_m_s[k], m[i] = measured_m[i];
  }
  update_axes(t, v, m, 3);
}

void StageController::update(const std::array<double, kMaxAxes>& target_m,
                             const std::array<double, kMaxAxes>& velocity_m_s,
                             const std::array<double, kMaxAxes>& measured_m) noexcept {
  update_axes(target_m, velocity_m_s, measured_m, axes_);
}

void StageController::update_axes(const std::array<double, kMaxAxes>& target_m,
                                  const std::array<double, kMaxAxes>& velocity_m_s,
                                  const std::array<double, kMaxAxes>& measured_m, int count) noexcept {
  for (std::size_t i = 0; i < static_cast<std::size_t>(count); ++i) {
    const auto k = i;
    if (parked_[i]) continue;
    if (track_[i]) {
      auto& t = *track_[i];
      // The first tick (and the first after an emergency stop) starts from where the axis is.
      if (!started_ || stopped_) t.reset(measured_m[i], stopped_ ? 0.0 : t.voltage_V());
      ref_[i] = motion::ReferenceSample{target_m[k], velocity_m_s[k], 0.0};
      since_update_s_[i] = 0.0;
      if (fast_) continue;  // updated at every loop tick by drive(i, measured)
      t.set_reference(ref_[i]);
      t.update(measured_m[i]);
      continue;
    }
    auto& c = *ctrl_[i];
    // A changed target (teleoperation moves it) is tracked with its velocity; an unchanged
    // one is left alone so that the controller settles into hold.
    if (stopped_ || c.target_m() != target_m[k] || velocity_m_s[k] != 0.0)
      c.set_target(target_m[k], velocity_m_s[k]);
    c.update(measured_m[i]);
  }
  stopped_ = false;
  started_ = true;
}

devices::DriveBlock StageController::drive(int i, double measured_m) noexcept {
  const auto iu = static_cast<std::size_t>(i);
  if (fast_ && started_ && !stopped_ && track_[iu] && !parked_[iu]) {
    const auto& r = ref_[iu];
    track_[iu]->set_reference(motion::ReferenceSample{r.x_m + r.v_m_s * since_update_s_[iu], r.v_m_s, 0.0});
    track_[iu]->update(measured_m);
    since_update_s_[iu] += tick_s_;
  }
  return drive(i);
}

devices::DriveBlock StageController::drive(int i) noexcept {
  auto& buf = samples_[static_cast<std::size_t>(i)];
  if (parked_[static_cast<std::size_t>(i)]) {
    for (auto& d : buf) d = stickslip::DriveSegment::to(parked_V_[static_cast<std::size_t>(i)]);
    devices::DriveBlock b;
    b.segments = buf.data();
    b.count = static_cast<int>(buf.size());
    return b;
  }
  if (auto* t = track_[static_cast<std::size_t>(i)].get()) {
    for (auto& d : buf) d = t->next_drive(sample_period_s_);
    const auto& op = t->operating_point();
    devices::DriveBlock b;
    b.segments = buf.data();
    b.count = static_cast<int>(buf.size());
    b.amplitude_V = op.amplitude_V;
    b.frequency_Hz = op.frequency_Hz;
    b.direction = op.direction == stickslip::Direction::kBackward ? -1 : 1;
    return b;
  }
  auto& c = *ctrl_[static_cast<std::size_t>(i)];
  for (auto& d : buf) d = c.next_drive(sample_period_s_);
  const auto& g = c.generator();
  devices::DriveBlock b;
  b.segments = buf.data();
  b.count = static_cast<int>(buf.size());
  b.amplitude_V = g.amplitude_V();
  b.frequency_Hz = g.frequency_Hz();
  b.direction = g.direction() == stickslip::Direction::kBackward ? -1 : 1;
  return b;
}

void StageController::park(int i) noexcept {
  const auto iu = static_cast<std::size_t>(i);
  if (!track_[iu] || parked_[iu] || stopped_) return;
  parked_V_[iu] = last_voltage_V(i);
  parked_[iu] = true;
}

void StageController::unpark(int i, double measured_m) noexcept {
  const auto iu = static_cast<std::size_t>(i);
  if (!parked_[iu]) return;
  parked_[iu] = false;
  track_[iu]->reset(measured_m, parked_V_[iu]);
}

void StageController::resume(int i, double measured_m, double u_V) noexcept {
  const auto iu = static_cast<std::size_t>(i);
  if (!track_[iu] || stopped_) return;
  parked_[iu] = false;
  track_[iu]->reset(measured_m, u_V);
  ref_[iu] = motion::ReferenceSample{measured_m, 0.0, 0.0};
  since_update_s_[iu] = 0.0;
}

void StageController::emergency_stop() noexcept {
  parked_.fill(false);
  for (auto& c : ctrl_)
    if (c) c->emergency_stop();
  for (auto& t : track_)
    if (t) t->emergency_stop();
  stopped_ = true;
}

}  // namespace mc::platform
