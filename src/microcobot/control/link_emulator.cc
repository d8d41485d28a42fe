#include "microcobot/control/link_emulator.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::control {

void LinkParams::validate() const {
  require(std::isfinite(delay_s) && delay_s >= 0.0 && delay_s <= 10.0, "link.delay_s",
          "must be within [0, 10] s", delay_s);
  require(std::isfinite(jitter_s) && jitter_s >= 0.0 && jitter_s <= delay_s, "link.jitter_s",
          "must be within [0, delay_s]", jitter_s);
  require(std::isfinite(loss) && loss >= 0.0 && loss < 1.0, "link.loss", "must be within [0, 1)", loss);
}

EmulatedLink::EmulatedLink(const LinkParams& params, double period_s) : p_(params), rng_(params.seed) {
  p_.validate();
  require(std::isfinite(period_s) && period_s > 0.0, "link period", "must be > 0 s", period_s);
  // Every sample still in flight: the longest delay's worth, and a margin.
  ring_.resize(static_cast<std::size_t>(std::ceil((p_.delay_s + p_.jitter_s) / period_s)) + 4);
}

void EmulatedLink::send(const LinkSample& s) noexcept {
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

bool EmulatedLink::receive(double now_s, LinkSample& out) noexcept {
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

}  // namespace mc::control
