#pragma once
/// @file
/// How long the network takes to carry a stream's samples, and how late each one is. The transit
/// of a sample is this end's clock at its arrival minus the sender's stamp: the network's delay
/// plus the offset between the two ends' clocks, which need no synchronisation. Its estimate is
/// the lowest transit over the last one to two `window_s` (a minimum over two buckets): the
/// fastest the network has carried a sample. A sample's lateness is its transit minus that
/// estimate: how long ago, beyond the fastest delivery, it was measured.
///
/// Why it matters (the cable pulled under load): samples queued in a socket,
/// the kernel or a starved receive thread while the link was down arrive in a burst afterwards,
/// each looking new to a timeout counted from its arrival. A backlog 100 ms old would re-engage
/// a coupling across a cable that is still out. Judged by its lateness, it is as stale as it is.
///
/// The buckets turn only when samples arrive: through an outage, however long, the estimate is
/// the one from before it, so the backlog that ends it is judged against the route as it was. A
/// route that became slower for good (or a sender's clock stepped back) is learned within two
/// windows of samples; until then its samples count as late, which errs on the safe side. The
/// first samples of a new stream cannot be judged (there is no route to compare with yet).
/// Never allocates; noexcept.

namespace mc::net {

class TransitEstimate {
 public:
  /// Throws mc::Error unless 0.01 <= window_s <= 60.
  explicit TransitEstimate(double window_s = 1.0);

  /// A sample that took `transit_s` (s), arriving at `now_s` (this end's clock, s). Returns its
  /// lateness (s, >= 0): 0 for the fastest yet, infinite for a non-finite input.
  double observe(double transit_s, double now_s) noexcept;
  /// The lowest transit over the last one to two windows (s); infinite before the first sample.
  double estimate_s() const noexcept { return estimate_s_; }
  /// Forget the route (a new stream from another sender).
  void reset() noexcept;

 private:
  double window_s_;
  double estimate_s_;
  double bucket_min_s_, previous_min_s_;  // lowest transit in this window and the one before
  double bucket_start_s_;
};

}  // namespace mc::net
