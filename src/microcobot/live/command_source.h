#pragma once
/// @file
/// An input to the live platform's loop: the console, the microscope link, the vendor
/// protocols, the remote master, the scripted demo, or a caller's own. Each is polled on the
/// loop at every operator tick; the CommandArbiter (command_arbiter.h) gives control of the
/// coupling to one of them, and only that one fills the coupling's input. Every call is on the
/// loop thread and must be real-time safe: no allocation, lock, exception or I/O (a source fed
/// by another thread takes its commands from a single-producer ring).

#include <string_view>

#include "microcobot/live/console_command.h"
#include "microcobot/platform/platform.h"
#include "microcobot/runtime/fixed_rate_loop.h"
#include "microcobot/teleop/teleoperation.h"

namespace mc::live {

/// What a source is offered at one operator tick.
struct SourceTick {
  const runtime::TickInfo& tick;  ///< loop time (the scene's, since its (re)start)
  platform::Platform& platform;
};

/// How much a source asks for control of the coupling at one tick.
enum class Claim {
  kNone,     ///< it does not drive (it may still act on what is not the slave: the microscope)
  kStandby,  ///< it drives when no source is active (the console without a client in control:
             ///< its input, not fresh, holds the stage)
  kActive,   ///< it asks to drive now
};

/// What a source asks of the arbiter at one tick.
struct SourceRequest {
  Claim claim = Claim::kNone;
  bool estop = false;  ///< latch the e-stop: every device to its safe state
  bool reset = false;  ///< release the e-stop this source latched (an explicit reset)
};

/// The coupling's input for a console command (the console's and the remote master's): its
/// velocity, goal, gripper and rotary parts, with `fresh` and the command's deadman; the rotary
/// goal turned at `theta_speed_rad_s`. The microscope's parts are not the coupling's.
teleop::ConsoleInput coupling_input(const ConsoleCommand& c, bool fresh, double theta_speed_rad_s) noexcept;

class CommandSource {
 public:
  virtual ~CommandSource() = default;
  /// Its name in the status and the events ("console", "protocol", ...).
  virtual std::string_view name() const noexcept = 0;
  /// Takes what arrived since the last tick and says how much it asks for control. Every source,
  /// every tick, in the arbiter's order, before any drives.
  virtual SourceRequest poll(const SourceTick& t) noexcept = 0;
  /// Fills the coupling's input (world coordinates): called on the holder only. Its freshness
  /// (`in.fresh`) and deadman (`in.deadman`) are what the coupling obeys: without both, the
  /// stage holds.
  virtual void drive(const SourceTick& t, teleop::ConsoleInput& in) noexcept = 0;
  /// Control passed from it to another source: it forgets its goal. The arbiter has made every
  /// axis hold already.
  virtual void released(const SourceTick&) noexcept {}
  /// After the tick's input is set, every source: what it publishes or starts from it.
  virtual void publish(const SourceTick&) noexcept {}
  /// A new scene (the platform rebuilt): it forgets what it had.
  virtual void reset() noexcept {}
};

}  // namespace mc::live
