#pragma once
/// @file
/// What the vendor drivers (pi-gcs2, anc300, smaract-mcs2) share: one controller per connection,
/// driven by a bus thread, with three position-controlled axes (devices/device.h) as its views.
///
///   loop (RT)     command_target_m() -> atomics      update(): fault() once the bus faulted
///                 enter_safe_state() -> a safe-state request (atomic counter)
///   bus thread    every poll period: a pending safe-state request first (the controller's stop),
///                 then the controller's cycle (send the latest targets, poll the positions),
///                 positions and their wall-clock stamp published through atomics
///   configure()   off the loop: (re)connects (TCP or serial line, LineClient::open) and runs the
///   controller's handshake unless the bus
///                 is up and healthy; a bus that faulted is reconnected here (Platform::recover)
///
/// Any failure on the bus (a reply later than the timeout, a truncated or garbled reply, a
/// controller error, a lost connection) faults the bus: the thread sends the controller's safe
/// state if the connection still stands, closes it and ends; every axis' update() then calls
/// fault() and the platform puts every device in its safe state at the same tick. The
/// measurements are stale (the coupling disengages, as with net/remote_slave.h) once the last
/// position is older than `stale_timeout_s` or the bus faulted. Nothing here allocates, locks,
/// throws or blocks on the loop's side.

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

#include "microcobot/devices/device.h"
#include "microcobot/drivers/line_client.h"

namespace mc::drivers {

/// The timing of a bus (docs/parameters.md, "Vendor drivers").
struct BusTiming {
  double connect_timeout_s =
      2.0;                       ///< TCP connect (a serial open is immediate) and the handshake's first reply
  double reply_timeout_s = 0.1;  ///< every reply; a later one faults the bus
  double poll_period_s = 0.002;  ///< one bus cycle: targets out, positions in
  double stale_timeout_s = 0.05;  ///< positions older than this are stale
  void validate() const;
};

/// The timing options every bus driver's `connection` takes (timeout_s, connect_timeout_s,
/// poll_s, stale_s), each over its default in `timing`; a value out of its range is refused naming
/// the option (line_client.h, connection_number).
BusTiming bus_timing(const Connection& c, BusTiming timing = {});
/// Their names, for check_connection_options.
inline constexpr std::string_view kBusTimingOptions = "timeout_s, connect_timeout_s, poll_s, stale_s";

/// A failure on the bus (the bus thread's own exception: it never crosses to the loop).
class BusFault : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class BusController {
 public:
  using Clock = std::chrono::steady_clock;
  /// X, Y, Z and, on a controller that drives it, the rotary axis under the gripper (index 3: its
  /// position as the platform's rotary axis gives it, the arc at the rotor's contact radius).
  static constexpr std::size_t kMaxAxes = 4;
  BusController(std::string driver, Connection connection, BusTiming timing);
  virtual ~BusController();
  BusController(const BusController&) = delete;
  BusController& operator=(const BusController&) = delete;

  /// Off the loop (an axis' on_configure): nothing when the bus runs healthy; else connects within
  /// the connect timeout, runs the handshake and starts the bus thread. Throws mc::Error naming
  /// the connection and what went wrong (the axis then stays in Fault).
  void configure();
  /// Ends the bus thread and closes the connection (idempotent). Derived destructors call it.
  void shutdown() noexcept;

  // The loop's side: real-time safe.
  void set_target(int axis, double target_m) noexcept;
  void arm(int axis, bool on) noexcept;
  void request_safe_state() noexcept { safe_requests_.fetch_add(1, std::memory_order_acq_rel); }
  double position_m(int axis) const noexcept {
    return position_m_[static_cast<std::size_t>(axis)].load(std::memory_order_relaxed);
  }
  bool fresh() const noexcept;
  bool faulted() const noexcept { return faulted_.load(std::memory_order_acquire); }

  // Any thread but the loop.
  std::string fault_reason() const;
  const std::string& identity() const { return identity_; }
  const std::string& driver() const { return driver_; }
  /// Safe states the bus thread carried out (tests: the controller's stop was sent).
  std::uint64_t safe_states_sent() const { return safe_done_.load(std::memory_order_acquire); }
  /// Bus cycles completed since the start (benchmarks, tests).
  std::uint64_t cycles() const { return cycles_.load(std::memory_order_relaxed); }

 protected:
  /// After connect: identity, axes, modes, servo, referencing; the initial positions published.
  /// Throws mc::Error (configuration) or BusFault.
  virtual void handshake(LineClient& bus) = 0;
  /// One bus cycle. Throws BusFault.
  virtual void cycle(LineClient& bus) = 0;
  /// The controller's safe state (stop every axis ...). Throws BusFault.
  virtual void safe_state(LineClient& bus) = 0;

  // For the derived controllers (bus thread).
  struct Targets {
    std::array<double, kMaxAxes> m{};
    std::array<bool, kMaxAxes> wanted{};  ///< armed and given since armed
  };
  Targets targets() const noexcept;
  void publish_position(int axis, double m) noexcept;
  void publish_stamp() noexcept;  ///< the positions just published are fresh
  Clock::time_point reply_deadline() const;
  /// The reply timeout as a duration.
  Clock::duration reply_timeout() const;
  Clock::time_point deadline_in(double s) const;
  const Connection& connection() const { return connection_; }
  const BusTiming& timing() const { return timing_; }
  bool stopping() const { return stop_.load(std::memory_order_relaxed); }

 private:
  void run() noexcept;
  void fail(const std::string& reason) noexcept;

  std::string driver_;
  Connection connection_;
  BusTiming timing_;
  LineClient bus_;
  std::thread thread_;
  std::string identity_;
  std::atomic<bool> stop_{false}, faulted_{false}, running_{false};
  std::atomic<std::uint64_t> safe_requests_{0}, safe_done_{0}, cycles_{0};
  std::uint64_t safe_seen_ = 0;  // bus thread
  std::array<std::atomic<double>, kMaxAxes> target_m_{}, position_m_{};
  std::array<std::atomic<bool>, kMaxAxes> armed_{}, given_{};
  std::atomic<std::int64_t> stamp_ns_{0};
  mutable std::mutex reason_mutex_;  // never taken on the loop
  std::string reason_;

 protected:
  void set_identity(std::string id) { identity_ = std::move(id); }
};

/// One stage axis of a bus controller: position-controlled (the controller, or the driver's bus
/// thread, closes the loop), the platform's targets in, the controller's positions out.
class BusAxis final : public devices::SlaveAxis {
 public:
  /// `controller` must outlive the axis (the driver set's factory keeps it in a shared_ptr).
  BusAxis(std::string name, std::shared_ptr<BusController> controller, int index, double sample_period_s,
          double max_voltage_V);
  double sample_period_s() const override { return period_s_; }
  double max_voltage_V() const override { return max_V_; }
  void command_drive(const devices::DriveBlock&) noexcept override {}  // never called
  double position_m() const override { return controller_->position_m(index_); }
  bool at_end_stop() const override { return false; }  // the controller's limits refuse the move
  bool position_controlled() const override { return true; }
  void command_target_m(double target_m, double velocity_m_s) noexcept override;
  bool measurement_fresh() const override { return controller_->fresh(); }
  void update(double dt_s) noexcept override;
  void enter_safe_state() noexcept override;
  const BusController& controller() const { return *controller_; }

 protected:
  void on_configure() override { controller_->configure(); }
  void on_activate() override { controller_->arm(index_, true); }

 private:
  std::shared_ptr<BusController> controller_;
  int index_;
  double period_s_, max_V_;
};

}  // namespace mc::drivers
