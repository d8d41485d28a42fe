#include "microcobot/motion/sawtooth_generator.h"

#include <algorithm>

namespace mc::motion {

void SawtoothGenerator::command(double amplitude_V, double frequency_Hz, Direction direction) noexcept {
  next_amp_ = std::max(0.0, amplitude_V);
  next_freq_ = std::max(1e-3, frequency_Hz);
  next_dir_ = direction;
  if (phase_ == Phase::kIdle) latch();
}

void SawtoothGenerator::latch() noexcept {
  amp_ = next_amp_;
  freq_ = next_freq_;
  dir_ = next_dir_;
  // The abrupt edge must leave time for the slow one.
  amp_ = std::min(amp_, 0.5 * slew_ / freq_);
}

void SawtoothGenerator::start(double u_V) noexcept {
  latch();
  u_ = std::max(0.0, u_V);
  stop_requested_ = false;
  phase_ = Phase::kRise;
}

void SawtoothGenerator::halt() noexcept {
  u_ = 0.0;
  phase_ = Phase::kIdle;
  stop_requested_ = false;
  wait_ = 0.0;
}

double SawtoothGenerator::rate(Phase ph) const noexcept {
  const double edge = amp_ / slew_;
  const double slow = amp_ / std::max(1.0 / freq_ - edge, 1e-12);
  const bool abrupt = (ph == Phase::kRise) == (dir_ == Direction::kBackward);
  return abrupt ? slew_ : slow;
}

stickslip::DriveSegment SawtoothGenerator::next(double dt_s) noexcept {
  stickslip::DriveSegment seg;
  double left = dt_s;
  // U turns here: a corner of the path, at the time elapsed in this interval.
  auto corner = [&] { seg.add_corner((dt_s - left) / dt_s, u_); };
  if (phase_ != Phase::kIdle && amp_ <= 0.0 && u_ <= 0.0) {
    // A zero-amplitude period: 0 V, but the period clock keeps running (controllers sample on it).
    u_ = 0.0;
    wait_ += left;
    const double period = 1.0 / freq_;
    if (wait_ >= period) {
      wait_ -= period;
      ++periods_;
      latch();
      if (stop_requested_) {
        phase_ = Phase::kIdle;
        stop_requested_ = false;
        wait_ = 0.0;
      } else {
        phase_ = Phase::kRise;
      }
    }
    seg.end_V = u_;
    return seg;
  }
  wait_ = 0.0;
  // At most a few phase changes per call (each phase lasts >= one slew-limited edge).
  for (int guard = 0; guard < 4 && left > 0.0 && phase_ != Phase::kIdle; ++guard) {
    if (phase_ == Phase::kRise) {
      const double r = rate(Phase::kRise);
      if (u_ >= amp_) {
        corner();
        phase_ = Phase::kFall;
        continue;
      }
      const double need = (amp_ - u_) / r;
      if (need > left) {
        u_ += r * left;
        left = 0.0;
      } else {
        u_ = amp_;
        left -= need;
        corner();
        phase_ = Phase::kFall;
      }
    } else {
      const double r = rate(Phase::kFall);
      const double need = u_ > 0.0 ? u_ / r : 0.0;
      if (need > left) {
        u_ -= r * left;
        left = 0.0;
      } else {
        u_ = 0.0;
        left -= need;
        corner();
        ++periods_;
        latch();
        if (stop_requested_) {
          phase_ = Phase::kIdle;
          stop_requested_ = false;
        } else {
          phase_ = Phase::kRise;
        }
      }
    }
  }
  seg.end_V = u_;
  return seg;
}

}  // namespace mc::motion
