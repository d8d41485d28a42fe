#include "microcobot/net/wire_emulator.h"

#include <algorithm>

#include "microcobot/core/error.h"
#include "microcobot/net/topics.h"

namespace mc::net {

bool impairs(const teleop::LinkParams& p) { return p.delay_s > 0 || p.jitter_s > 0 || p.loss > 0; }

WireEmulator::WireEmulator(const teleop::LinkParams& params, double rate_Hz) {
  params.validate();
  require_positive(rate_Hz, "rate_Hz");
  for (const TopicSpec& spec : topic_table()) {
    const auto c = static_cast<std::size_t>(spec.channel);
    teleop::LinkParams p = params;
    p.seed = params.seed + c;  // independent losses and jitter per topic
    if (spec.reliability == Reliability::kReliable) p.loss = 0.0;
    lines_[c] = std::make_unique<teleop::EmulatedLinkOf<Stamped>>(p, 1.0 / rate_Hz);
    delivered_s_[c] = -1.0;
  }
}

void WireEmulator::arrive(double now_s, const NetSample& s) noexcept {
  // Strictly increasing send times, so that the newest of a burst taken in one tick wins (an
  // e-stop set and released within a tick ends released).
  last_s_ = std::max(now_s, last_s_ + 1e-9);
  lines_[static_cast<std::size_t>(s.channel)]->send({last_s_, s});
}

std::uint64_t WireEmulator::lost() const {
  std::uint64_t n = 0;
  for (const auto& l : lines_) n += l->lost();
  return n;
}

}  // namespace mc::net
