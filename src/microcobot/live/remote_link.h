#pragma once
/// @file
/// The far end of a distributed platform as the slave process sees it: the master process,
/// over the network (net/remote_master.h). The live platform's RemoteSource (remote_source.h)
/// polls it on the loop at the operator rate, in place of the console, and lets it publish what
/// the slave measured. Real-time safe: no allocation, lock, exception or I/O in either call (a
/// network implementation only pushes to and pops from its link's rings).

#include <cstdint>

#include "microcobot/live/console_command.h"
#include "microcobot/platform/platform.h"

namespace mc::live {

/// What the far end asked for at one operator tick.
struct RemoteRequest {
  bool fresh = false;  ///< its commands are fresh (else the stage holds: the watchdog)
  bool estop = false;  ///< the far end latched its e-stop: every device to its safe state
  bool reset = false;  ///< the far end released its e-stop: reset ours if it latched it
};

class RemoteLink {
 public:
  virtual ~RemoteLink() = default;
  /// Takes what arrived since the last call: the latest command (world coordinates, as the
  /// console's) into `command` when one came, and the far end's requests. `t_s` is loop time.
  virtual RemoteRequest poll(double t_s, ConsoleCommand& command) noexcept = 0;
  /// Publishes the slave's measurements (positions, forces, gripper) after the tick's poll.
  virtual void publish(const platform::Platform& platform) noexcept = 0;
};

}  // namespace mc::live
