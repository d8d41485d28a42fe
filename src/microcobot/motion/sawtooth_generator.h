#pragma once
/// @file
/// Real-time sawtooth synthesis for stepping mode (thesis §2.2.2, Fig. 2.3; §2.7 Fig. 2.18): each
/// period rises from 0 V to the amplitude A and falls back to 0 V; forward = slow rise + abrupt
/// (slew-limited) fall, backward = abrupt rise + slow fall. The amplitude, frequency and direction
/// are latched at period boundaries (where U = 0 V), so commands never make the voltage jump. A
/// generator started from a non-zero voltage (the scanning voltage) first completes the current
/// half-period from there (bumpless entry into stepping).

#include <cstdint>

#include "microcobot/stickslip/breakaway_table.h"
#include "microcobot/stickslip/drive_segment.h"

namespace mc::motion {

using stickslip::Direction;

class SawtoothGenerator {
 public:
  explicit SawtoothGenerator(double slew_rate_V_s = 1.0e6) : slew_(slew_rate_V_s) {}

  /// Sets the waveform used from the next period boundary on (or at once when idle).
  void command(double amplitude_V, double frequency_Hz, Direction direction) noexcept;
  /// Starts stepping from the present output voltage `u_V` (bumpless).
  void start(double u_V) noexcept;
  /// Requests a stop at the next period boundary (U = 0 V).
  void stop_at_period_end() noexcept { stop_requested_ = true; }
  /// Stops at once (emergency stop): output 0 V.
  void halt() noexcept;
  /// Advances by `dt_s` and returns U over that interval: its corners (the top of each ramp and
  /// each period's start, wherever they fall) and the voltage at its end. Never allocates.
  stickslip::DriveSegment next(double dt_s) noexcept;

  bool running() const noexcept { return phase_ != Phase::kIdle; }
  double output_V() const noexcept { return u_; }
  double amplitude_V() const noexcept { return amp_; }
  double frequency_Hz() const noexcept { return freq_; }
  Direction direction() const noexcept { return dir_; }
  /// Completed periods since construction (a period completes when U returns to 0 V).
  std::int64_t periods() const noexcept { return periods_; }

 private:
  enum class Phase { kIdle, kRise, kFall };
  void latch() noexcept;
  double rate(Phase ph) const noexcept;
  double slew_;
  double u_ = 0.0;
  double wait_ = 0.0;  ///< time spent in a zero-amplitude period
  double amp_ = 0.0, freq_ = 1000.0;
  Direction dir_ = Direction::kForward;
  double next_amp_ = 0.0, next_freq_ = 1000.0;
  Direction next_dir_ = Direction::kForward;
  Phase phase_ = Phase::kIdle;
  bool stop_requested_ = false;
  std::int64_t periods_ = 0;
};

}  // namespace mc::motion
