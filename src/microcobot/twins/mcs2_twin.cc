#include "microcobot/twins/mcs2_twin.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>

#include <fmt/format.h>

#include "microcobot/core/error.h"

namespace mc::twins {

namespace mcs2 = drivers::mcs2;

namespace {
constexpr double kPmPerM = 1e12;
constexpr double kNdegPerRad = 180.0 / std::numbers::pi * 1e9;
/// Relative moves and position offsets are kept well inside int64 so that sums cannot overflow.
constexpr std::int64_t kMaxUnits = 4'000'000'000'000'000'000;
using Clock = std::chrono::steady_clock;
}  // namespace

void Mcs2TwinParams::validate() const {
  require(!serial.empty() && serial.size() < 64 && serial.find_first_of("\"\r\n;") == std::string::npos,
          "mcs2.serial", "must be one word of fewer than 64 characters without quotes or ';'");
  require(no_sensor_channels < (1u << TwinStage::kMaxAxes), "mcs2.no_sensor_channels",
          "must name channels 0 to 3 (a bit each)", static_cast<double>(no_sensor_channels));
  require(std::isfinite(calibration_s) && calibration_s >= 0 && calibration_s <= 60, "mcs2.calibration_s",
          "must be within [0, 60] s", calibration_s);
  require(velocity_pm_s >= 0, "mcs2.velocity_pm_s", "must be >= 0", static_cast<double>(velocity_pm_s));
  require(velocity_ndeg_s >= 0, "mcs2.velocity_ndeg_s", "must be >= 0", static_cast<double>(velocity_ndeg_s));
  require(step_frequency_Hz >= 1 && step_frequency_Hz <= mcs2::kMaxStepFrequency_Hz, "mcs2.step_frequency_Hz",
          "must be within [1, 20000] Hz", step_frequency_Hz);
  require(step_amplitude >= 1 && step_amplitude <= mcs2::kFullAmplitude, "mcs2.step_amplitude",
          "must be within [1, 65535] (65535: 100 V)", step_amplitude);
}

Mcs2Twin::Mcs2Twin(TwinStage& stage, Mcs2TwinParams params)
    : stage_(stage),
      params_(std::move(params)),
      channels_(std::clamp(stage.axis_count(), 3, TwinStage::kMaxAxes)) {
  params_.validate();
  for (int n = 0; n < channels_; ++n) {
    Mcs2Channel& c = ch_[static_cast<std::size_t>(n)];
    c.sensor_present = (params_.no_sensor_channels & (1u << n)) == 0;
    c.velocity = rotary(n) ? params_.velocity_ndeg_s : params_.velocity_pm_s;
    c.step_frequency_Hz = params_.step_frequency_Hz;
    c.step_amplitude = params_.step_amplitude;
    c.positioner_type = rotary(n) ? 309 : 300;
    c.target = stage_units(n);
  }
}

std::int64_t Mcs2Twin::from_si(int n, double si) const {
  const double v = si * (rotary(n) ? kNdegPerRad : kPmPerM);
  return std::isfinite(v) ? std::llround(std::clamp(v, -1e18, 1e18)) : 0;
}

double Mcs2Twin::to_si(int n, std::int64_t units) const {
  return static_cast<double>(units) / (rotary(n) ? kNdegPerRad : kPmPerM);
}

std::int64_t Mcs2Twin::stage_units(int n) const { return from_si(n, stage_.axis(n).position); }
std::int64_t Mcs2Twin::min_units(int n) const {
  return from_si(n, stage_.min(n)) + ch_[static_cast<std::size_t>(n)].offset;
}
std::int64_t Mcs2Twin::max_units(int n) const {
  return from_si(n, stage_.max(n)) + ch_[static_cast<std::size_t>(n)].offset;
}

void Mcs2Twin::push_error(int code) {
  if (code == mcs2::kNoError) return;
  ++pushed_;
  if (errors_.size() >= mcs2::kErrorQueueDepth) {
    errors_.back() = mcs2::kQueueOverflow;  // SCPI: the newest entry says the queue overflowed
    return;
  }
  errors_.push_back(code);
}

bool Mcs2Twin::channel_ok(int n) {
  if (n >= 0 && n < channels_) return true;
  push_error(mcs2::kInvalidChannelIndex);
  return false;
}

bool Mcs2Twin::accepted(TwinStage::Refusal r) {
  switch (r) {
    case TwinStage::Refusal::kNone:
      return true;
    case TwinStage::Refusal::kHalted:
      push_error(mcs2::kMovementLocked);
      return false;
    case TwinStage::Refusal::kOtherOperator:
      push_error(mcs2::kPermissionDenied);
      return false;
    case TwinStage::Refusal::kBusy:
      push_error(mcs2::kAborted);
      return false;
    case TwinStage::Refusal::kUnreachable:
      push_error(mcs2::kAborted);
      return false;
  }
  return false;
}

bool Mcs2Twin::closed_loop_ready(int n) {
  const Mcs2Channel& c = ch_[static_cast<std::size_t>(n)];
  if (!c.sensor_present) return push_error(mcs2::kNoSensorPresent), false;
  if (c.sensor_mode == mcs2::kSensorOff) return push_error(mcs2::kSensorDisabled), false;
  if (!c.amplifier) return push_error(mcs2::kAmplifierDisabled), false;
  return true;
}

bool Mcs2Twin::moving(int n) const {
  const Mcs2Channel& c = ch_[static_cast<std::size_t>(n)];
  const TwinStage::Axis a = stage_.axis(n);
  return a.stepping || c.referencing || Clock::now() < c.calibrating_until || (c.closed_loop && !a.on_target);
}

std::uint32_t Mcs2Twin::state(int n) const {
  namespace s = mcs2::channel_state;
  const Mcs2Channel& c = ch_[static_cast<std::size_t>(n)];
  const bool is_moving = moving(n);
  const bool sensing = c.sensor_present && c.sensor_mode != mcs2::kSensorOff;
  std::uint32_t bits = 0;
  if (is_moving) bits |= s::kActivelyMoving;
  // Closed loop while it moves to its target, and after it for the hold time (-1: forever).
  if (sensing && c.closed_loop && (is_moving || c.hold_ms != 0)) bits |= s::kClosedLoopActive;
  if (Clock::now() < c.calibrating_until) bits |= s::kCalibrating;
  if (c.referencing) bits |= s::kReferencing;
  if (c.sensor_present) bits |= s::kSensorPresent;
  if (c.calibrated) bits |= s::kIsCalibrated;
  if (c.referenced) bits |= s::kIsReferenced;
  if (c.range_limit) bits |= s::kRangeLimitReached;
  if (c.move_failed) bits |= s::kMovementFailed;
  if (c.amplifier) bits |= s::kAmplifierEnabled;
  if (sensing && c.closed_loop && !is_moving) bits |= s::kInPosition;
  return bits;
}

void Mcs2Twin::update() {
  const bool halted = stage_.halted();
  const auto now = Clock::now();
  // The client whose motion ran lost control (it went away, a console user took over, the e-stop):
  // the platform holds every axis where it is, so no channel goes on to its target.
  if (owner_ != 0 && !stage_.controls(owner_)) {
    owner_ = 0;
    for (int n = 0; n < channels_; ++n) {
      Mcs2Channel& c = ch_[static_cast<std::size_t>(n)];
      // Short of its target by more than twice the platform's on-target tolerance (1 um; theta:
      // 0.0115 deg), or a reference or a step run cut off: the move failed.
      const std::int64_t short_of = std::llabs(c.target - (stage_units(n) + c.offset));
      if (c.referencing || stage_.axis(n).stepping ||
          (c.closed_loop && short_of > (rotary(n) ? 23'000'000 : 2'000'000)))
        c.move_failed = true;
      c.target = stage_units(n) + c.offset;
      c.closed_loop = c.referencing = false;
    }
  }
  for (int n = 0; n < channels_; ++n) {
    Mcs2Channel& c = ch_[static_cast<std::size_t>(n)];
    const TwinStage::Axis a = stage_.axis(n);
    if (halted && (c.referencing || a.stepping || (c.closed_loop && !a.on_target))) {
      // The e-stop ended the move: the platform forgot its goal, the channel holds where it is.
      c.move_failed = true;
      c.referencing = false;
      c.closed_loop = false;
      c.target = stage_units(n) + c.offset;
    }
    if (c.referencing && a.on_target && !a.stepping) {
      c.referencing = false;
      c.referenced = true;
    }
    if (c.calibrating_until != Clock::time_point{} && now >= c.calibrating_until) {
      c.calibrating_until = {};
      c.calibrated = true;
    }
  }
}

bool Mcs2Twin::send_goal(ClientId client, int speed_channel) {
  TwinStage::Goal goal{};
  auto pace = [&](int n, double cap) {
    const auto v = ch_[static_cast<std::size_t>(n)].velocity;
    return v <= 0 ? cap : std::min(cap, to_si(n, v));
  };
  double linear = stage_.max_speed(0);
  for (int n = 0; n < channels_; ++n) {
    const Mcs2Channel& c = ch_[static_cast<std::size_t>(n)];
    goal[static_cast<std::size_t>(n)] =
        c.closed_loop ? to_si(n, c.target - c.offset) : stage_.axis(n).position;
    // X, Y, Z move as one, straight: at the moved channel's VEL, or the slowest of those holding a
    // target when the rotary channel moves alone.
    if (!rotary(n) && c.closed_loop && rotary(speed_channel)) linear = std::min(linear, pace(n, linear));
  }
  if (!rotary(speed_channel)) linear = pace(speed_channel, stage_.max_speed(0));
  const double theta =
      channels_ > TwinStage::kTheta ? pace(TwinStage::kTheta, stage_.max_speed(TwinStage::kTheta)) : 0.0;
  if (!accepted(stage_.move_to(client, goal, linear, theta))) return false;
  owner_ = client;
  return true;
}

void Mcs2Twin::move(ClientId client, int n, const mcs2::Command& cmd) {
  if (!channel_ok(n)) return;
  if (cmd.args.empty()) return push_error(mcs2::kMissingParameter);
  if (cmd.args.size() > 1) return push_error(mcs2::kParameterNotAllowed);
  const auto value = mcs2::parse_rounded(cmd.args[0]);
  if (!value) return push_error(mcs2::kDataTypeError);
  Mcs2Channel& c = ch_[static_cast<std::size_t>(n)];
  if (!c.amplifier) return push_error(mcs2::kAmplifierDisabled);
  if (c.move_mode == mcs2::kScanAbsolute || c.move_mode == mcs2::kScanRelative)
    return push_error(mcs2::kFeatureNotImplemented);
  if (c.move_mode == mcs2::kStep) {
    if (*value < -mcs2::kMaxSteps || *value > mcs2::kMaxSteps) return push_error(mcs2::kDataOutOfRange);
    if (*value == 0) return;
    const double volts =
        std::min(stage_.max_voltage_V(), c.step_amplitude * mcs2::kFullAmplitude_V / mcs2::kFullAmplitude);
    if (!accepted(stage_.step(client, n, volts, c.step_frequency_Hz, *value > 0 ? +1 : -1,
                              *value > 0 ? *value : -*value))) {
      c.move_failed = true;
      return;
    }
    owner_ = client;
    // The platform runs either one closed-loop goal or open-loop runs: the other channels' targets
    // are dropped, every channel holds where it is.
    for (int k = 0; k < channels_; ++k) {
      Mcs2Channel& o = ch_[static_cast<std::size_t>(k)];
      if (o.closed_loop) o.target = stage_units(k) + o.offset;
      o.closed_loop = false;
      o.referencing = false;
    }
    c.move_failed = c.range_limit = false;
    return;
  }
  if (!closed_loop_ready(n)) return;
  // Positions are known only relative to power-up before the reference: no absolute move then.
  if (c.move_mode == mcs2::kAbsolute && !c.referenced) return push_error(mcs2::kNotReferenced);
  if (c.referencing) return push_error(mcs2::kBusyReferencing);
  const std::int64_t v = std::clamp(*value, -kMaxUnits, kMaxUnits);
  std::int64_t target = v;
  if (c.move_mode == mcs2::kRelative) target += c.closed_loop ? c.target : stage_units(n) + c.offset;
  const std::int64_t lo = min_units(n), hi = max_units(n);
  const Mcs2Channel before = c;
  c.range_limit = target < lo || target > hi;
  if (c.range_limit) push_error(mcs2::kRangeLimitReached);  // it goes as far as the travel allows
  c.target = std::clamp(target, lo, hi);
  c.closed_loop = true;
  c.move_failed = false;
  if (!send_goal(client, n)) {
    c = before;
    c.move_failed = true;
  }
}

void Mcs2Twin::reference(ClientId client, int n) {
  if (!channel_ok(n) || !closed_loop_ready(n)) return;
  Mcs2Channel& c = ch_[static_cast<std::size_t>(n)];
  const Mcs2Channel before = c;
  // The reference mark is the stage's home: the scale's 0 there (with or without auto zero).
  c.offset = 0;
  c.target = 0;
  c.closed_loop = true;
  c.range_limit = c.move_failed = false;
  if (!send_goal(client, n)) {
    c = before;
    c.move_failed = true;
    return;
  }
  c.referencing = true;
  c.referenced = false;
}

void Mcs2Twin::stop(ClientId client, int n) {
  if (!channel_ok(n)) return;
  if (!may_stop(client)) return;  // nothing of another operator's motion stops
  Mcs2Channel& c = ch_[static_cast<std::size_t>(n)];
  c.target = stage_units(n) + c.offset;
  c.referencing = false;
  c.calibrating_until = {};
  // Another channel still on its way keeps going; this one holds where it is.
  bool others = false;
  for (int k = 0; k < channels_; ++k)
    if (k != n && ch_[static_cast<std::size_t>(k)].closed_loop && !stage_.axis(k).on_target) others = true;
  if (others && c.closed_loop && stage_.controls(client)) {
    send_goal(client, n);
  } else {
    stage_.stop(client);
  }
}

std::string Mcs2Twin::on_line(ClientId client, std::string_view line) {
  update();
  std::string reply;
  // After a command failed, the line's later set commands and actions are skipped (they may
  // depend on what failed: no move at a velocity that was refused), its queries still answered.
  bool failed = false;
  for (const std::string_view text : mcs2::split_commands(line)) {
    mcs2::Command c;
    if (const int e = mcs2::parse_command(text, c); e != mcs2::kNoError) {
      push_error(e);
      failed = true;
      continue;
    }
    if (failed && !c.query) continue;
    const std::uint64_t pushed = pushed_;
    execute(client, c, reply);
    failed |= pushed_ != pushed;
  }
  return reply;
}

void Mcs2Twin::execute(ClientId client, const mcs2::Command& c, std::string& reply) {
  const std::string& h = c.header;
  auto answer = [&](const std::string& text) { reply += text + std::string(mcs2::kEol); };
  const bool bare = c.args.empty();
  if (c.query && !bare) return push_error(mcs2::kParameterNotAllowed);
  if (h.rfind("CHAN:", 0) == 0) return channel_property(client, c.index, c, reply);
  const int modules = (channels_ + 2) / 3;
  if (c.query) {
    if (h == "*IDN" && c.index < 0) return answer("microcobot,MCS2 digital twin," + params_.serial + ",1.0");
    if (h == "DEV:SNUM") return answer("\"" + params_.serial + "\"");
    if (h == "DEV:NOCH") return answer(std::to_string(channels_));
    if (h == "DEV:NOBM") return answer(std::to_string(modules));
    if (h == "DEV:STAT") return answer(std::to_string(stage_.halted() ? mcs2::kDeviceMovementLocked : 0u));
    if (h == "DEV:EST:MODE") return answer("0");
    if (h == "SYST:ERR:COUN") return answer(std::to_string(errors_.size()));
    if (h == "SYST:ERR" || h == "SYST:ERR:NEXT") {
      const int code = errors_.empty() ? mcs2::kNoError : errors_.front();
      if (!errors_.empty()) errors_.pop_front();
      return answer(mcs2::format_error(code));
    }
    if (h == "MOD:STAT" || h == "MOD:TEMP") {
      if (c.index < 0 || c.index >= modules) return push_error(mcs2::kInvalidModuleIndex);
      if (h == "MOD:TEMP") return answer("25.0");
      bool sensors = false;
      for (int n = 3 * c.index; n < std::min(channels_, 3 * c.index + 3); ++n)
        sensors |= ch_[static_cast<std::size_t>(n)].sensor_present;
      return answer(std::to_string(sensors ? mcs2::kModuleSensorModulePresent : 0u));
    }
    return push_error(mcs2::kUndefinedHeader);
  }
  if (h == "*CLS" && bare) return errors_.clear();
  if (h == "MOVE") return move(client, c.index, c);
  if (h == "REF" || h == "CAL" || h == "STOP") {
    if (!bare) return push_error(mcs2::kParameterNotAllowed);
    if (h == "REF") return reference(client, c.index);
    if (h == "STOP") return stop(client, c.index);
    if (!channel_ok(c.index)) return;
    Mcs2Channel& ch = ch_[static_cast<std::size_t>(c.index)];
    if (!ch.sensor_present) return push_error(mcs2::kNoSensorPresent);
    if (ch.referencing) return push_error(mcs2::kBusyReferencing);
    // The twin's sensor needs no calibration: the channel reports calibrating for a while, then
    // calibrated; the physical position is lost as on the controller (referenced again after).
    ch.calibrated = false;
    ch.referenced = false;
    ch.calibrating_until = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                              std::chrono::duration<double>(params_.calibration_s));
    return;
  }
  push_error(mcs2::kUndefinedHeader);
}

}  // namespace mc::twins
