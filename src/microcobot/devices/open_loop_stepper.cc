#include "microcobot/devices/open_loop_stepper.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::devices {

OpenLoopStepper::OpenLoopStepper(int samples_per_tick, double sample_period_s, double slew_rate_V_s)
    : generator_(slew_rate_V_s), sample_period_s_(sample_period_s), slew_rate_V_s_(slew_rate_V_s) {
  require(samples_per_tick >= 1, "samples_per_tick", "must be at least 1", samples_per_tick);
  require_positive(sample_period_s, "sample_period_s");
  samples_.assign(static_cast<std::size_t>(samples_per_tick), stickslip::DriveSegment{});
}

void OpenLoopStepper::start(double amplitude_V, double frequency_Hz, int direction, std::int64_t periods,
                            double u_V) noexcept {
  generator_.halt();
  direction_ = direction < 0 ? -1 : 1;
  periods_ = periods;
  running_ = periods > 0;
  if (!running_) return;
  generator_.command(amplitude_V, frequency_Hz,
                     direction_ < 0 ? stickslip::Direction::kBackward : stickslip::Direction::kForward);
  // The axis rarely rests at 0 V (the position controller holds it with the PE's static
  // deflection, anywhere in 0..100 V). The run first goes from there to where its slow edge
  // starts (up: 0 V, down: the amplitude) along the abrupt edge, at the amplifier's slew rate:
  // the slider slips there, it is not dragged (a slow fall from a hold voltage above the
  // amplitude would pull it back by the PE's deflection). Then whole periods follow, as
  // `stickslip simulate` plays them from 0 V.
  entry_V_ = std::max(0.0, u_V);
  start_periods_ = generator_.periods();
}

void OpenLoopStepper::halt() noexcept {
  generator_.halt();
  entry_V_ = -1.0;
  running_ = false;
}

DriveBlock OpenLoopStepper::drive() noexcept {
  for (auto& s : samples_) {
    if (!running_) {
      s = stickslip::DriveSegment::to(0.0);
      continue;
    }
    if (entry_V_ >= 0.0) {
      const double target = direction_ > 0 ? 0.0 : generator_.amplitude_V();
      const double step = slew_rate_V_s_ * sample_period_s_;
      entry_V_ = std::abs(target - entry_V_) <= step ? target : entry_V_ + (target > entry_V_ ? step : -step);
      s = stickslip::DriveSegment::to(entry_V_);
      if (entry_V_ == target) {
        generator_.start(target);  // from the start of its slow edge
        start_periods_ = generator_.periods();
        entry_V_ = -1.0;
      }
      continue;
    }
    // The last period ends at its boundary (0 V): the generator stops there by itself.
    if (periods_done() + 1 >= periods_) generator_.stop_at_period_end();
    s = generator_.next(sample_period_s_);
    if (periods_done() >= periods_ || !generator_.running()) halt();
  }
  DriveBlock b;
  b.segments = samples_.data();
  b.count = static_cast<int>(samples_.size());
  b.amplitude_V = generator_.amplitude_V();
  b.frequency_Hz = running_ ? generator_.frequency_Hz() : 0.0;
  b.direction = running_ ? direction_ : 0;
  return b;
}

}  // namespace mc::devices
