#include "microcobot/platform/stage_controller.h"

#include "microcobot/core/error.h"

namespace mc::platform {

StageController::StageController(const control::PositionControlParams& params,
                                 const stickslip::StickSlipParams& model, const control::StepMap& map,
                                 int samples_per_tick, double sample_period_s)
    : sample_period_s_(sample_period_s) {
  require(samples_per_tick >= 1, "samples_per_tick", "must be at least 1", samples_per_tick);
  require_positive(sample_period_s, "sample_period_s");
  for (std::size_t i = 0; i < 3; ++i) {
    ctrl_[i] = std::make_unique<control::PositionController>(params, model, map);
    samples_[i].assign(static_cast<std::size_t>(samples_per_tick), stickslip::DriveSegment{});
  }
}

void StageController::update(const Eigen::Vector3d& target_m, const Eigen::Vector3d& velocity_m_s,
                             const std::array<double, 3>& measured_m) noexcept {
  for (std::size_t i = 0; i < 3; ++i) {
    auto& c = *ctrl_[i];
    const auto k = static_cast<Eigen::Index>(i);
    // A changed target (teleoperation moves it) is tracked with its velocity; an unchanged
    // one is left alone so that the controller settles into hold.
    if (stopped_ || c.target_m() != target_m[k] || velocity_m_s[k] != 0.0)
      c.set_target(target_m[k], velocity_m_s[k]);
    c.update(measured_m[i]);
  }
  stopped_ = false;
}

DriveBlock StageController::drive(int i) noexcept {
  auto& c = *ctrl_[static_cast<std::size_t>(i)];
  auto& buf = samples_[static_cast<std::size_t>(i)];
  for (auto& d : buf) d = c.next_drive(sample_period_s_);
  const auto& g = c.generator();
  DriveBlock b;
  b.segments = buf.data();
  b.count = static_cast<int>(buf.size());
  b.amplitude_V = g.amplitude_V();
  b.frequency_Hz = g.frequency_Hz();
  b.direction = g.direction() == stickslip::Direction::kBackward ? -1 : 1;
  return b;
}

void StageController::emergency_stop() noexcept {
  for (auto& c : ctrl_) c->emergency_stop();
  stopped_ = true;
}

}  // namespace mc::platform
