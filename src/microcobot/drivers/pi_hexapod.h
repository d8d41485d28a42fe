#pragma once
/// @file
/// The `pi-hexapod` driver: the platform's 6-DOF parallel positioner (`positioner: parallel`,
/// devices/parallel_positioner.h) on a PI C-887 hexapod controller over TCP (or `microcobot serve
/// --emulate gcs2-hexapod`), selected by the configuration:
///
///     positioner: parallel
///     parallel_positioner: {driver: pi-hexapod, connection: "192.168.10.7:50000,timeout_s=0.2"}
///
/// The controller plans and runs each pose move itself: start_move() hands the checked
/// trajectory's goal (and its tool point's speed, as VLS) to the bus thread, which sends it as
/// `MOV X Y Z U V W`; the pose comes back from `POS?`, moving from `#5`, on target from `ONT?`
/// (drivers/pi_hexapod_controller.h). The safe state sends `#24`, and stop() while a move runs (holding, it
/// keeps the held pose). A fault of the bus (a reply later than the timeout, a lost connection, a controller
/// error, a reply that does not parse) faults the device at its next update(), and the platform puts every
/// device in its safe state; the next configure() (the platform's reset) reconnects.
///
/// The loop's side (update, start_move, stop, enter_safe_state and the getters) neither allocates,
/// locks, throws nor does I/O: a ring push, atomics and a triple-buffer read.

#include <cstdint>
#include <memory>
#include <string>

#include "microcobot/devices/parallel_positioner.h"
#include "microcobot/drivers/pi_hexapod_controller.h"
#include "microcobot/platform/platform_config.h"

namespace mc::drivers {

class PiHexapod final : public devices::ParallelPositioner {
 public:
  /// `geometry`: the positioner's kinematics, for the moves the platform plans and checks
  /// (motion::check_move) before it starts them.
  PiHexapod(std::string name, std::shared_ptr<PiHexapodController> controller,
            const motion::ParallelGeometryParams& geometry);

  /// Takes the bus thread's newest status; faults the device once the bus faulted.
  void update(double dt_s) noexcept override;
  /// Stops the controller (#24): every queued move dropped, the hexapod holding where it stops.
  void enter_safe_state() noexcept override { send_stop(); }  // #24 whatever it was doing

  const motion::ParallelKinematics& kinematics() const noexcept override { return kinematics_; }
  /// Sends `checked`'s goal (MOV) and its speed (VLS, mm/s of the tool point's max_speed_m_s):
  /// false, and nothing is sent, unless Active, the bus fresh, at rest, and the trajectory starting
  /// at reference_pose() (within 1 nm and 1 nrad in every entry of R and d).
  bool start_move(const motion::PoseTrajectory& checked) noexcept override;
  void stop() noexcept override;
  const motion::PlatformTransform& measured_pose() const noexcept override { return status_.measured; }
  /// The pose the controller holds: the last move's goal, or where a stop left it.
  const motion::PlatformTransform& reference_pose() const noexcept override { return status_.held; }
  /// A move sent and not yet acknowledged by the bus, a stop not yet settled, or `#5` non-zero;
  /// false once the bus faulted (the controller was sent #24 if the connection stood).
  bool moving() const noexcept override;
  /// Not moving and `ONT?` 1 on every axis.
  bool at_rest() const noexcept override { return !moving() && status_.on_target; }
  /// 0: the controller does not report its struts' drive.
  double max_leg_voltage_V() const noexcept override { return 0.0; }

  const PiHexapodController& controller() const { return *controller_; }

 protected:
  void on_configure() override;

 private:
  /// `#24` through the bus thread (one at a time).
  void send_stop() noexcept;
  std::shared_ptr<PiHexapodController> controller_;
  motion::ParallelKinematics kinematics_;
  HexapodStatus status_;        ///< the loop's copy of the bus thread's newest
  std::uint64_t seq_ = 0;       ///< the last number given to a move or a stop
  std::uint64_t move_seq_ = 0;  ///< the last move pushed
  std::uint64_t stop_seq_ = 0;  ///< the last stop asked
};

/// The positioner `pi-hexapod` of `config` (`parallel_positioner.connection`: HOST:PORT, a C-887
/// listens on kC887DefaultPort; the options of pi_hexapod_params()). Builds, opens nothing.
std::unique_ptr<devices::ParallelPositioner> make_pi_hexapod(const platform::PlatformConfig& config);

}  // namespace mc::drivers
