#pragma once
/// @file
/// The link emulator between two processes (`serve --link-delay
/// --link-jitter --link-loss`): what the DDS link delivers to the loop is held back by the
/// emulated delay and jitter, and lost with the emulated probability, before the remote end
/// (remote_slave.h, remote_master.h) applies it. One emulated line per channel
/// (teleop::EmulatedLinkOf): each keeps the newest sample that has arrived, as a keep-last-1
/// reader does. Only best-effort topics lose samples: DDS retransmits the reliable ones (e-stop,
/// engaged), which the emulator only delays. Each process emulates what it receives, so two
/// processes with `--link-delay D` have a round trip of 2 D plus the network's own.
/// Preallocated: nothing on the loop path allocates.

#include <array>
#include <memory>

#include "microcobot/net/net_sample.h"
#include "microcobot/teleop/link_emulator.h"

namespace mc::net {

/// True when `p` impairs a link at all (any delay, jitter or loss).
bool impairs(const teleop::LinkParams& p);

class WireEmulator {
 public:
  /// `rate_Hz`: the fastest channel's rate (sizes the lines). Throws InvalidParams.
  WireEmulator(const teleop::LinkParams& params, double rate_Hz);

  /// A sample the link delivered at loop time `now_s`: into flight.
  void arrive(double now_s, const NetSample& s) noexcept;
  /// Calls `apply(sample)` once for each channel whose newest arrived sample is new since the
  /// last call.
  template <class Apply>
  void deliver(double now_s, Apply&& apply) noexcept {
    for (std::size_t c = 0; c < kChannelCount; ++c) {
      Stamped s;
      if (lines_[c]->receive(now_s, s) && s.sent_s > delivered_s_[c]) {
        delivered_s_[c] = s.sent_s;
        apply(s.sample);
      }
    }
  }
  std::uint64_t lost() const;

 private:
  struct Stamped {
    double sent_s = 0.0;
    NetSample sample;
  };
  std::array<std::unique_ptr<teleop::EmulatedLinkOf<Stamped>>, kChannelCount> lines_;
  std::array<double, kChannelCount> delivered_s_{};
  double last_s_ = -1.0;
};

}  // namespace mc::net
