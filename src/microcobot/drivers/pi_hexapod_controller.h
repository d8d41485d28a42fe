#pragma once
/// @file
/// The bus side of the `pi-hexapod` driver: a PI C-887 hexapod controller speaking the hexapod
/// dialect of GCS 2.0 (drivers/gcs2_hexapod.h) over TCP, driven by the bus thread of
/// bus_controller.h (connect, handshake, poll, fault, reconnect at the next configure). The loop's
/// side is drivers/pi_hexapod.h; the two meet in a ring and a snapshot (runtime/spsc_ring.h,
/// runtime/latest_value.h) and two atomics, never a lock:
///
///   loop -> bus   SpscRing<HexapodMove>: a move's goal and speed, numbered; `stop_seq`: the
///                 number of the last stop (every move numbered before it is dropped unsent), with
///                 BusController::request_safe_state() so that the stop goes out at once
///   bus -> loop   LatestValue<HexapodStatus>: the measured pose, the pose held, the moves and
///                 the stop done, moving (#5) and on target (ONT?)
///
/// Commands (docs/hardware.md, "pi-hexapod"):
///
///   configure  *IDN? (must name a C-887), ERR? until 0 (the stale error queue drained), SAI? ALL
///              (X Y Z U V W listed), KEN? (ZERO: poses in the root coordinate system), SPI? (the
///              pivot), FRF? and, when unreferenced, FRF X Y Z U V W, ERR?, then FRF? until referenced
///              (within reference_timeout_s), VLS?, ERR? until 0 again, POS?
///   each cycle a move from the ring: [VLS v, ERR?] (when its speed differs from the last),
///              MOV X x Y y Z z U u V v W w, ERR? (must read 0); then POS?, #5, ONT?
///   stop, safe state  #24 (stop all), ERR? (0 or 10, "stopped by command")
///
/// Poses are in mm and deg on the wire (%.6f: 1 nm, 1 udeg), SI in the platform; they convert by
/// motion/pose.h's PI convention about the controller's pivot (R = Rx(U) Ry(V) Rz(W), d = t +
/// (I - R) c; PI's hexapod manuals, MS207E §3.7.4), the conversions the twin makes
/// (twins/gcs2_hexapod_twin.h).

#include <array>
#include <atomic>
#include <cstdint>
#include <string>

#include "microcobot/drivers/bus_controller.h"
#include "microcobot/motion/pose.h"
#include "microcobot/runtime/latest_value.h"
#include "microcobot/runtime/spsc_ring.h"

namespace mc::drivers {

/// The C-887's TCP port out of the box (PI's hexapod manuals; the twin's default too).
inline constexpr std::uint16_t kC887DefaultPort = 50000;

struct PiHexapodParams {
  /// The bus's timing: poll 5 ms (three round trips a cycle: POS?, #5, ONT?), stale 0.1 s, reply
  /// timeout 0.1 s, connect 2 s (docs/parameters.md, "Vendor drivers").
  BusTiming timing{2.0, 0.1, 0.005, 0.1};
  bool reference = true;              ///< FRF an unreferenced hexapod at configure (else refuse it)
  double reference_timeout_s = 60.0;  ///< FRF's longest wait
  void validate() const;
};

/// `connection` options: timeout_s, connect_timeout_s, poll_s, stale_s, reference (0|1),
/// reference_timeout_s. A serial line is refused (the driver speaks TCP).
PiHexapodParams pi_hexapod_params(const Connection& connection);

/// One pose move for the bus thread.
struct HexapodMove {
  std::uint64_t seq = 0;           ///< numbered by the loop, from 1
  motion::PlatformTransform goal;  ///< {H}
  double speed_mm_s = 0.0;         ///< VLS for it; 0 keeps the controller's
};

/// The controller's state as the bus thread last read it.
struct HexapodStatus {
  motion::PlatformTransform measured;  ///< POS?, {H}
  motion::PlatformTransform held;      ///< the last move's goal, or where a stop left it
  std::uint64_t move_done = 0;         ///< the last move sent (or dropped by a stop)
  std::uint64_t stop_done = 0;         ///< the last stop sent and settled (#5 reads 0 after it)
  bool moving = false;                 ///< #5: some axis moves
  bool on_target = false;              ///< ONT?: every axis on target
};

class PiHexapodController final : public BusController {
 public:
  /// Moves the ring holds: one runs at a time, the rest is margin.
  static constexpr std::size_t kMoveRing = 8;
  PiHexapodController(Connection connection, PiHexapodParams params);
  ~PiHexapodController() override { shutdown(); }
  const PiHexapodParams& params() const { return params_; }

  // The loop's side: real-time safe (a ring push, atomics).
  /// False when the ring is full (nothing is sent).
  bool push_move(const HexapodMove& m) noexcept { return moves_.push(m); }
  /// Drops every move numbered up to `seq` and sends #24 at once.
  void request_stop(std::uint64_t seq) noexcept {
    stop_seq_.store(seq, std::memory_order_release);
    request_safe_state();
  }
  /// The newest status (one reader: the loop, or the control thread between loop runs).
  HexapodStatus status() noexcept { return status_.read(); }

  /// The pivot point read at configure (SPI?), in {P} [m].
  const Eigen::Vector3d& pivot_m() const { return pivot_m_; }
  /// MOV lines sent (tests).
  std::uint64_t moves_sent() const { return moves_sent_.load(std::memory_order_relaxed); }

 protected:
  void handshake(LineClient& bus) override;
  void cycle(LineClient& bus) override;
  void safe_state(LineClient& bus) override;

 private:
  std::string query(LineClient& bus, const std::string& line, double timeout_s = 0.0);
  /// A set command, then ERR?: throws BusFault naming the code and its text unless it is 0 (or `also_ok`).
  void command(LineClient& bus, const std::string& line, int also_ok = 0);
  /// A query of the six axes (POS? X Y Z U V W ...): their values in order. Throws BusFault.
  std::array<double, 6> read_six(LineClient& bus, const std::string& mnemonic);
  motion::PlatformTransform read_pose(LineClient& bus);
  void send_move(LineClient& bus, const HexapodMove& m);

  PiHexapodParams params_;
  runtime::SpscRing<HexapodMove> moves_{kMoveRing};
  runtime::LatestValue<HexapodStatus> status_;
  std::atomic<std::uint64_t> stop_seq_{0};
  std::atomic<std::uint64_t> moves_sent_{0};
  // Bus thread only.
  HexapodStatus bus_;  ///< what the next publish says
  Eigen::Vector3d pivot_m_ = Eigen::Vector3d::Zero();
  double vls_mm_s_ = 0.0;        ///< the controller's VLS as last set or read
  std::uint64_t stop_sent_ = 0;  ///< the stop sent, settled once #5 reads 0
};

}  // namespace mc::drivers
