#pragma once
/// @file
/// Who drives the live platform's coupling: one CommandSource (command_source.h) at a time.
///
/// At every operator tick the arbiter polls every source in its order (the first added ranks
/// highest), then gives control to the highest-ranked source that is active, or, when none is,
/// to the highest-ranked one on standby; none of either: nobody drives and the haptic masters
/// keep the coupling. Only the holder fills the coupling's input, whose freshness and deadman
/// the coupling obeys (a stale or released holder leaves the stage holding). A hand-over makes
/// every axis hold where it is measured (Platform::hold) and tells the old holder it was
/// released, so the new holder starts from rest and the old one's goal is forgotten. A source's
/// e-stop request latches the platform's e-stop; its reset request releases only an e-stop that
/// this source latched.
///
/// Adding a source is one add() call by whoever assembles the live platform
/// (LiveParams::sources): neither the arbiter nor LivePlatform changes. Real-time safe: no
/// allocation after the sources are added.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "microcobot/live/command_source.h"

namespace mc::live {

class CommandArbiter {
 public:
  static constexpr std::size_t kMaxSources = 8;

  /// Adds `source` below those added before. Not owned: it outlives the arbiter. Before the loop
  /// runs. Throws mc::InvalidParams when kMaxSources are there already.
  void add(CommandSource& source);

  /// What a tick decided beyond the input: a source released the e-stop it latched, and the
  /// platform is to be reset (by the control thread, between two runs: it may allocate).
  struct Decision {
    bool reset = false;
  };
  /// One operator tick: polls every source (latching the e-stop at once when one asks),
  /// hands control over (or keeps it), and lets the holder fill `in` (left as given when nobody
  /// drives).
  Decision tick(const SourceTick& t, teleop::ConsoleInput& in) noexcept;
  /// After the input is set: every source's publish().
  void publish(const SourceTick& t) noexcept;
  /// A new scene: nobody holds control, every source forgets.
  void reset() noexcept;

  std::size_t size() const noexcept { return count_; }
  const CommandSource& source(std::size_t i) const noexcept { return *sources_[i]; }
  /// The source holding control after the last tick, -1 for none. Any thread.
  int holder() const noexcept { return holder_.load(std::memory_order_relaxed); }
  /// Its name ("" for none). Any thread (the names are the sources' constants).
  std::string_view holder_name() const noexcept;
  /// Hand-overs since the start. Any thread.
  std::uint64_t handovers() const noexcept { return handovers_.load(std::memory_order_relaxed); }

 private:
  std::array<CommandSource*, kMaxSources> sources_{};
  std::size_t count_ = 0;
  std::atomic<int> holder_{-1};
  int estop_by_ = -1;  ///< the source that latched the e-stop (loop thread)
  std::atomic<std::uint64_t> handovers_{0};
};

}  // namespace mc::live
