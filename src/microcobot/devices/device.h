#pragma once
/// @file
/// The lifecycle every device of the platform follows (after ros2_control's hardware
/// components): configure() allocates and checks, activate() arms, update() runs on the
/// real-time path, deactivate() disarms. Whatever happens, a device can be put in its safe
/// state at once (zero force, axes hold at 0 V) with enter_safe_state(), which is real-time
/// safe and idempotent; fault() does that and latches the fault until reconfigured.
///
///     Unconfigured --configure--> Inactive --activate--> Active
///          ^                        ^  |                   |
///          |                        |  +----deactivate-----+
///          +-------configure--------+--- Fault <--fault()--+ (from any state)
///
/// A device that is not Active ignores commands and outputs its safe state; update() is
/// called at every tick once configured, whatever the state (a simulated device keeps its
/// physics running; a hardware driver keeps its bus alive).

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

#include "microcobot/stickslip/drive_segment.h"

namespace mc::devices {

enum class Lifecycle { kUnconfigured, kInactive, kActive, kFault };

std::string_view to_string(Lifecycle state);

class Device {
 public:
  explicit Device(std::string name) : name_(std::move(name)) {}
  virtual ~Device() = default;
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;

  const std::string& name() const { return name_; }
  Lifecycle state() const { return state_; }
  bool active() const { return state_ == Lifecycle::kActive; }

  /// Unconfigured/Inactive/Fault -> Inactive. May allocate; throws mc::Error on failure
  /// (the device then stays in Fault).
  void configure();
  /// Inactive -> Active. Throws mc::InvalidInput from any other state.
  void activate();
  /// Active -> Inactive, through the safe state.
  void deactivate();
  /// Safe state now and latch Fault. Real-time safe.
  void fault() noexcept;

  /// One exchange with the device on the real-time path: apply the latest command, advance
  /// `dt_s` (a simulated device steps its model; a hardware driver talks to its bus), latch
  /// new measurements. Called at every tick once configured. Must not allocate, lock, throw
  /// or block.
  virtual void update(double dt_s) noexcept = 0;
  /// Puts outputs in the safe state (zero force / 0 V / hold). Real-time safe, idempotent.
  virtual void enter_safe_state() noexcept = 0;

 protected:
  virtual void on_configure() {}
  virtual void on_activate() {}
  virtual void on_deactivate() {}

 private:
  std::string name_;
  Lifecycle state_ = Lifecycle::kUnconfigured;
};

/// A planar vector in SI units.
struct Vec2 {
  double x = 0.0;
  double y = 0.0;
};

/// A spatial vector in SI units.
struct Vec3 {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;
};

/// The dual-stage haptic interface (Pantograph + Haptuator, ch. 3): handle position in,
/// force out, and the handle's controls: the deadman (enable) switch, the clutch (indexing)
/// button and a thumb wheel that jogs the slave's Z axis.
class HapticMaster : public Device {
 public:
  using Device::Device;
  virtual Vec2 handle_position_m() const = 0;
  virtual bool enabled() const = 0;
  virtual bool clutch() const = 0;
  virtual double jog_m_s() const = 0;
  /// Counts fresh readings: a driver whose bus stalls stops counting (the watchdog's input).
  virtual std::uint64_t reading_count() const = 0;
  /// Force to render on the handle; ignored unless Active.
  virtual void command_force_N(Vec2 force) noexcept = 0;
};

/// The TéléTweez haptic tweezers (ch. 4): opening of the tips in, grip force out.
class TweezersMaster : public Device {
 public:
  using Device::Device;
  virtual double opening_m() const = 0;
  virtual std::uint64_t reading_count() const = 0;
  /// Force to apply on each finger (closing positive is a squeeze felt as resistance);
  /// ignored unless Active.
  virtual void command_grip_force_N(double force) noexcept = 0;
};

/// What the slave controller sends an axis for one loop tick: the drive voltage of the tick,
/// one segment per sample period, and the sawtooth it comes from. A DAC-streaming driver plays
/// each segment's end voltage as its sample (a stick-slip sawtooth needs edges of a few us, far
/// faster than the loop); a driver with its own waveform generator programs the sawtooth
/// instead; the simulation follows each segment's path, corners included, and uses the
/// sawtooth for the break-away strain (thesis §2.7).
struct DriveBlock {
  const stickslip::DriveSegment* segments = nullptr;  ///< `count` consecutive segments
  int count = 0;
  double amplitude_V = 0.0;   ///< sawtooth amplitude
  double frequency_Hz = 0.0;  ///< sawtooth frequency (0: no sawtooth programmed)
  int direction = 0;          ///< +1 forward, -1 backward, 0 none
};

/// One stick-slip positioning axis of the slave stage (ch. 2): drive voltage out, position in.
/// Voltages are clamped to [0, max_voltage_V()] (the amplifier's range, at most 100 V).
class SlaveAxis : public Device {
 public:
  using Device::Device;
  /// Sample period of the drive voltage [s].
  virtual double sample_period_s() const = 0;
  virtual double max_voltage_V() const = 0;
  /// The samples to play during the next update(); ignored unless Active. The samples must
  /// stay valid until then.
  virtual void command_drive(const DriveBlock& block) noexcept = 0;
  /// Sensor reading of the carriage position [m].
  virtual double position_m() const = 0;
  /// Where the carriage is, for what it carries [m]: a simulated gripper's finger tips follow
  /// it. The truth in a simulation; for hardware the best knowledge there is, the sensor
  /// (a simulated gripper on a real stage: hardware in the loop, docs/hardware.md).
  virtual double carried_position_m() const { return position_m(); }
  /// True while the carriage rests against one of its end stops.
  virtual bool at_end_stop() const = 0;

  /// True for an axis closed in position beyond this process: the slave stage of a distributed
  /// platform (net/remote_slave.h), or a controller with its own position loop. The platform
  /// then sends it targets (command_target_m) and keeps its own stage controller aside;
  /// command_drive() is never called. Every axis of a platform must agree.
  virtual bool position_controlled() const { return false; }
  /// Target position and its velocity (m, m/s, stage coordinates) for a position-controlled
  /// axis, once per slave tick; ignored unless Active.
  virtual void command_target_m(double /*target_m*/, double /*velocity_m_s*/) noexcept {}
  /// False while the measurements are stale: a remote slave that went silent. The coupling
  /// then disengages (no force on the masters) and re-engages at the measured position once
  /// fresh readings return (re-indexed like a clutch). A local axis is always fresh.
  virtual bool measurement_fresh() const { return true; }
};

/// The slave micro-gripper: opening command out, opening and grip force in.
class Gripper : public Device {
 public:
  using Device::Device;
  virtual void command_opening_m(double opening) noexcept = 0;
  virtual double opening_m() const = 0;
  virtual double grip_force_N() const = 0;
  /// Force on the gripper from its contacts (the mount's force sensor), world frame [N].
  virtual Vec3 contact_force_N() const = 0;
  /// The opening the drive puts the fingers at with nothing between them: its open-loop model
  /// of its own actuation (force by vision's reference, vision_grip_force.h). NaN: none.
  virtual double free_opening_m() const { return std::nan(""); }
  /// The drive's release burst on or off (microworld/release.h, shake); a gripper whose drive has
  /// none ignores it (can_shake() false).
  virtual void command_shake(bool /*on*/) noexcept {}
  virtual bool can_shake() const { return false; }
  /// The 4-DOF PiezoGripper's vertical benders (thesis §1.1.4: "the vertical motion is used to
  /// align the fingertips"; microworld/bender_fingers.h): each finger's align drive [V], positive
  /// raises its tip. A gripper without them ignores the command (has_align_drives() false).
  virtual bool has_align_drives() const { return false; }
  virtual void command_align_V(const std::array<double, 2>& /*drives_V*/) noexcept {}
  /// The align drives in force [V] (zeros without them).
  virtual std::array<double, 2> align_V() const { return {}; }
  /// The align drives' range +-this [V] (0 without them).
  virtual double align_limit_V() const { return 0.0; }
  /// Each tip's vertical contact force on the substrate [N] (the tips' touch, by vision or a force
  /// sensor at the tip; zeros when the gripper reads none).
  virtual std::array<double, 2> tip_contact_N() const { return {}; }
};

}  // namespace mc::devices
