#pragma once
/// @file
/// The scripted demo: the pick-and-place operator of cell/pick_place_operator.h acting on the
/// simulated masters' hands, so that the coupling is driven as a person would drive it. Active
/// from the scene's start until the operator is done or gives up; then it says how the demo
/// ended (every outcome is shown to the operator) and the console has control again.

#include <atomic>
#include <limits>
#include <memory>
#include <string>
#include <string_view>

#include "microcobot/cell/pick_place_operator.h"
#include "microcobot/live/command_source.h"

namespace mc::live {

/// How the last scripted demo ended.
struct DemoResult {
  enum class Outcome { kNone, kRunning, kPlaced, kInserted, kMissed, kGaveUp };
  Outcome outcome = Outcome::kNone;
  std::string phase;  ///< the phase it is in, or gave up in
  double placement_error_m =
      std::numeric_limits<double>::quiet_NaN();  ///< part centre to target, horizontal (NaN: no part)
  double duration_s = 0.0;                       ///< since the demo started
  std::string reason;                            ///< why it gave up, or what it achieved, in words
  static std::string_view name(Outcome o);
};

class DemoSource final : public CommandSource {
 public:
  /// `placement_tolerance_m`: a part placed within it of its target counts as placed.
  explicit DemoSource(double placement_tolerance_m) : tolerance_m_(placement_tolerance_m) {}

  /// A new scene: the scripted operator `op` runs in it (null: no demo). Control thread, while
  /// the loop does not run.
  void start(std::unique_ptr<cell::PickPlaceOperator> op);
  /// The scripted operator drives now. Any thread.
  bool running() const noexcept { return running_.load(std::memory_order_relaxed); }
  /// Its phase's name while it runs (empty otherwise). Any thread.
  std::string phase_name() const;
  /// How the last demo ended, in words for `world` (the scene's: placed or inserted). Any thread.
  DemoResult result(bool scene_has_hole) const;

  std::string_view name() const noexcept override { return "demo"; }
  SourceRequest poll(const SourceTick& t) noexcept override;
  /// Nothing to fill: the simulated masters, whose hands the operator moves, drive the coupling.
  void drive(const SourceTick&, teleop::ConsoleInput&) noexcept override {}
  void publish(const SourceTick& t) noexcept override;

 private:
  double tolerance_m_;
  std::unique_ptr<cell::PickPlaceOperator> op_;
  bool finished_ = false;  // loop thread: the operator is done, the console has control
  std::atomic<bool> running_{false};
  std::atomic<int> phase_{0}, failed_phase_{0};
  // The result, written by the loop (outcome_ last, with release order).
  std::atomic<int> outcome_{0};  // DemoResult::Outcome
  std::atomic<double> error_m_{std::numeric_limits<double>::quiet_NaN()}, duration_s_{0.0};
};

}  // namespace mc::live
