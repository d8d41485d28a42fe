#pragma once
/// @file
/// A network link as the coupling system sees it: each sample sent at a fixed rate
/// arrives after a delay with jitter, or never (loss). Samples that arrive after a newer one are
/// discarded (what a receiver keeping the latest sample does with reordered datagrams), and the
/// receiver holds the latest sample until a newer one arrives. Deterministic for a seed.
/// Preallocated: send() and receive() never allocate (they run on the loop).

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "microcobot/core/rng.h"

namespace mc::teleop {

struct LinkParams {
  double delay_s = 0.0;   ///< one-way delay (mean)
  double jitter_s = 0.0;  ///< each sample's delay is uniform in [delay - jitter, delay + jitter], >= 0
  double loss = 0.0;      ///< probability that a sample is lost, [0, 1)
  std::uint64_t seed = 1;
  void validate() const;
};

/// Throws InvalidParams unless `period_s` is a finite period > 0.
void require_period(double period_s);

/// What crosses the link: a value and the sender's cumulative input energy (time-domain
/// passivity, passivity.h), stamped with the time it was sent.
struct LinkSample {
  double sent_s = 0.0;
  double value = 0.0;
  double energy_J = 0.0;
};

/// The link for any sample type with a `double sent_s` member (the DDS link's emulator sends
/// whole messages: net/wire_emulator.h).
template <class Sample>
class EmulatedLinkOf {
 public:
  /// `period_s`: the sending period (sizes the buffer for delay + jitter). Throws InvalidParams.
  EmulatedLinkOf(const LinkParams& params, double period_s) : p_(params), rng_(params.seed) {
    p_.validate();
    require_period(period_s);
    // Every sample still in flight: the longest delay's worth, and a margin.
    ring_.resize(static_cast<std::size_t>(std::ceil((p_.delay_s + p_.jitter_s) / period_s)) + 4);
  }
  /// Sends `s` at `s.sent_s` (non-decreasing). Never allocates.
  void send(const Sample& s) noexcept {
    ++sent_;
    const double u = rng_.uniform(), j = rng_.uniform(-1.0, 1.0);  // both drawn: one stream per seed
    if (u < p_.loss) {
      ++lost_;
      return;
    }
    if (count_ == ring_.size()) {  // cannot happen at the declared period; the oldest goes
      head_ = (head_ + 1) % ring_.size();
      --count_;
    }
    ring_[(head_ + count_) % ring_.size()] = {s.sent_s + std::max(0.0, p_.delay_s + p_.jitter_s * j), s};
    ++count_;
  }
  /// The latest sample that has arrived by `now_s`; false until the first one arrives.
  bool receive(double now_s, Sample& out) noexcept {
    // Deliver everything that has arrived; keep the newest by send time (older arrivals are stale).
    std::size_t kept = 0;
    for (std::size_t k = 0; k < count_; ++k) {
      InFlight& f = ring_[(head_ + k) % ring_.size()];
      if (f.arrival_s <= now_s) {
        if (!has_latest_ || f.sample.sent_s > latest_.sent_s) latest_ = f.sample;
        has_latest_ = true;
      } else {
        ring_[(head_ + kept) % ring_.size()] = f;  // compact the ones still in flight, in order
        ++kept;
      }
    }
    count_ = kept;
    if (has_latest_) out = latest_;
    return has_latest_;
  }
  std::uint64_t sent() const { return sent_; }
  std::uint64_t lost() const { return lost_; }

 private:
  struct InFlight {
    double arrival_s;
    Sample sample;
  };
  LinkParams p_;
  Rng rng_;
  std::vector<InFlight> ring_;  // in send order
  std::size_t head_ = 0, count_ = 0;
  Sample latest_{};
  bool has_latest_ = false;
  std::uint64_t sent_ = 0, lost_ = 0;
};

using EmulatedLink = EmulatedLinkOf<LinkSample>;

}  // namespace mc::teleop
