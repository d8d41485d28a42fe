#pragma once
/// @file
/// The master's targets at the slave's end of the network link: a jitter
/// buffer. Targets leave the master at 1 kHz stamped with its clock and arrive late, bunched or
/// not at all (delay, jitter, loss). Followed as they arrive, the slave's goal would stop at
/// every gap and jump at every burst. Here each axis' targets go through a
/// motion::SetpointStream read at the sender's time minus the transit, so the goal retraces
/// the master's motion, interpolated between the targets that arrived, `delay_s` (the stream's
/// look-ahead) behind; a target later than that holds the goal, which rejoins at the stream's
/// speed limit, never by a jump.
///
/// The transit (this end's clock minus the sender's stamp at arrival) is estimated by a
/// TransitEstimate (transit_estimate.h): its lowest value over the last one to two `window_s`,
/// the fastest the network has carried a target, clock offset included, so the two ends' clocks
/// need no synchronisation; a route that became slower is followed within two windows (a
/// minimum over two buckets: it never creeps, which would shift the read time, and the goal with
/// it, between new minima). Never allocates after construction.

#include <array>

#include "microcobot/motion/setpoint_stream.h"
#include "microcobot/net/transit_estimate.h"

namespace mc::net {

class TargetStream {
 public:
  using Axes3 = std::array<double, 3>;
  /// Allocates the three streams' rings here only.
  explicit TargetStream(const motion::SetpointStreamParams& stream, double window_s = 1.0);

  /// A target stamped `stamp_s` by the sender, arriving at `now_s` (this end's clock, s). An
  /// out-of-order one is dropped, and so is one stamped more than `kMaxStampLead_s` ahead of the
  /// sender's clock as learned so far (a forged or corrupt stamp would otherwise make every later
  /// target look out of order and freeze the goal). Returns whether it was taken.
  bool push(double stamp_s, const Axes3& target_m, double now_s) noexcept;
  static constexpr double kMaxStampLead_s = 0.5;
  /// The target to follow at `now_s`, advanced by `dt_s`.
  Axes3 sample(double now_s, double dt_s) noexcept;
  /// A new session (the sender came back): hold `target_m`, learn the transit anew.
  void reset(const Axes3& target_m) noexcept;
  /// The last sample() held because the targets were late or missing.
  bool holding() const noexcept { return holding_; }
  /// The transit estimate (s); infinite before the first target.
  double transit_s() const noexcept { return transit_.estimate_s(); }

 private:
  std::array<motion::SetpointStream, 3> axes_;
  TransitEstimate transit_;
  bool holding_ = true;
};

}  // namespace mc::net
