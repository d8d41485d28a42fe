#pragma once
/// @file
/// A network link as the coupling system sees it (issue #17): each sample sent at a fixed rate
/// arrives after a delay with jitter, or never (loss). Samples that arrive after a newer one are
/// discarded (what a receiver keeping the latest sample does with reordered datagrams), and the
/// receiver holds the latest sample until a newer one arrives. Deterministic for a seed.
/// Preallocated: send() and receive() never allocate (they run on the loop).

#include <cstddef>
#include <cstdint>
#include <vector>

#include "microcobot/core/rng.h"

namespace mc::control {

struct LinkParams {
  double delay_s = 0.0;   ///< one-way delay (mean)
  double jitter_s = 0.0;  ///< each sample's delay is uniform in [delay - jitter, delay + jitter], >= 0
  double loss = 0.0;      ///< probability that a sample is lost, [0, 1)
  std::uint64_t seed = 1;
  void validate() const;
};

/// What crosses the link: a value and the sender's cumulative input energy (time-domain
/// passivity, passivity.h), stamped with the time it was sent.
struct LinkSample {
  double sent_s = 0.0;
  double value = 0.0;
  double energy_J = 0.0;
};

class EmulatedLink {
 public:
  /// `period_s`: the sending period (sizes the buffer for delay + jitter). Throws InvalidParams.
  EmulatedLink(const LinkParams& params, double period_s);
  /// Sends `s` at `s.sent_s` (non-decreasing). Never allocates.
  void send(const LinkSample& s) noexcept;
  /// The latest sample that has arrived by `now_s`; false until the first one arrives.
  bool receive(double now_s, LinkSample& out) noexcept;
  std::uint64_t sent() const { return sent_; }
  std::uint64_t lost() const { return lost_; }

 private:
  struct InFlight {
    double arrival_s;
    LinkSample sample;
  };
  LinkParams p_;
  Rng rng_;
  std::vector<InFlight> ring_;  // in send order
  std::size_t head_ = 0, count_ = 0;
  LinkSample latest_;
  bool has_latest_ = false;
  std::uint64_t sent_ = 0, lost_ = 0;
};

}  // namespace mc::control
