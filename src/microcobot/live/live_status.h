#pragma once
/// @file
/// The live platform's status: what the console shows and the server publishes on
/// /platform/status, readable from any thread (LivePlatform::status()), and the loop's part of
/// it, published as atomics at every operator tick (LoopReadings).

#include <array>
#include <atomic>
#include <cstdint>
#include <optional>
#include <string>

#include "microcobot/devices/device.h"
#include "microcobot/live/demo_source.h"
#include "microcobot/live/live_task.h"
#include "microcobot/perception/vision_grip_force.h"
#include "microcobot/perception/vision_positioner.h"
#include "microcobot/platform/platform.h"

namespace mc::live {

/// What the loop reports, readable from any thread.
struct LiveStatus {
  double t_s = 0.0;  ///< live time since serve started (continues across scene restarts)
  bool estopped = false;
  bool demo = false;                              ///< the scripted operator is driving
  std::string demo_phase;                         ///< its phase (empty unless demo)
  bool console_fresh = false;                     ///< the controlling client's commands are fresh
  std::array<devices::Lifecycle, 6> lifecycle{};  ///< axes x, y, z, gripper, haptic, tweezers
  bool has_rotary = false;                        ///< the rotary axis under the gripper ...
  devices::Lifecycle rotary_lifecycle{};          ///< ... and its state
  std::uint64_t overruns = 0;
  std::uint64_t ticks = 0;  ///< loop ticks since the scene (re)started (overruns are of these)
  std::uint64_t restarts = 0;
  /// The camera: frames delivered and dropped (the loop could not hand them over)
  /// since the scene (re)started; the focal plane and the objective.
  bool camera = false;
  std::uint64_t camera_frames = 0, camera_dropped = 0;
  double focus_z_m = 0.0, focus_target_m = 0.0;
  int objective = 0;
  DemoResult demo_result;
  std::string last_error;              ///< the last failed request (reset refused, rebuild failed)
  std::optional<LiveTaskStatus> task;  ///< the supervised task (none without one)
  /// The stage positioned by vision (`stage.xy_sensor: vision`; none otherwise).
  std::optional<perception::PositionerStatus> vision;
  /// The grip force measured by vision (`vision_force.enabled`, a camera, the gripper's scene;
  /// none otherwise).
  std::optional<perception::VisionGripStatus> grip_vision;
  /// The gripper's tip levelling (Level tips; none without align drives).
  std::optional<platform::TipLevellingStatus> levelling;
  /// The source holding control of the coupling ("console", "protocol", "demo", "remote", a
  /// caller's; empty before the first tick).
  std::string control;
};

/// What the loop reads off the platform for the other threads, at every operator tick: the
/// time, the e-stop, the devices' lifecycles, the overruns and ticks, the microscope. Written by
/// the loop only (relaxed atomics: each value stands alone).
class LoopReadings {
 public:
  /// Loop thread; real-time safe. `t_live_s`: live time (continues across scene restarts).
  void publish(platform::Platform& p, double t_live_s) noexcept;
  /// Into `s` (any thread): t_s, estopped, lifecycle, has_rotary, rotary_lifecycle, overruns,
  /// ticks, camera_dropped, focus_z_m, focus_target_m, objective.
  void fill(LiveStatus& s) const noexcept;
  double t_s() const noexcept { return t_s_.load(std::memory_order_relaxed); }
  bool estopped() const noexcept { return estopped_.load(std::memory_order_relaxed); }
  /// Whether the gripper has align drives (its tips can be levelled). Any thread.
  bool has_levelling() const noexcept { return levelling_state_.load(std::memory_order_relaxed) >= 0; }
  /// Stopped for good: every device in its safe state (LivePlatform::stop).
  void set_stopped() noexcept { estopped_.store(true, std::memory_order_relaxed); }

 private:
  std::atomic<double> t_s_{0.0};
  std::atomic<bool> estopped_{false};
  std::atomic<std::uint64_t> ticks_{0}, overruns_{0}, camera_dropped_{0};
  std::array<std::atomic<int>, 6> lifecycle_{};
  std::atomic<int> rotary_lifecycle_{-1};  // -1: no rotary axis
  std::atomic<double> focus_z_m_{0.0}, focus_target_m_{0.0};
  std::atomic<int> objective_{0};
  // The tip levelling (platform::TipLevellingStatus; state -1: no align drives).
  std::atomic<int> levelling_state_{-1}, levelling_phase_{0}, levelling_passes_{0};
  std::atomic<const char*> levelling_failure_{""};
  std::atomic<double> levelling_before_m_{0.0}, levelling_misalignment_m_{0.0}, levelling_peak_N_{0.0};
};

}  // namespace mc::live
