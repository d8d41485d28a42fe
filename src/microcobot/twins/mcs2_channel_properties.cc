// The MCS2 twin's channel properties (`:CHAN<n>:<property>[?] [value]`): each one's range, unit
// and what setting it does to the channel (twins/mcs2_twin.h, docs/hardware.md).

#include <cstdlib>
#include <optional>

#include <fmt/format.h>

#include "microcobot/twins/mcs2_twin.h"

namespace mc::twins {

namespace mcs2 = drivers::mcs2;

namespace {

/// The positioner type codes the twin knows (SmarAct's table as kamzik3 lists it) and their names.
std::string_view positioner_name(int code) {
  switch (code) {
    case 300:
      return "SL...S1SS";
    case 301:
      return "SL...D1SS";
    case 309:
      return "SR...S1S5S";
    case 312:
      return "SR...S1S6S";
    default:
      return "Custom";
  }
}

}  // namespace

void Mcs2Twin::channel_property(ClientId client, int n, const mcs2::Command& c, std::string& reply) {
  if (!channel_ok(n)) return;
  Mcs2Channel& ch = ch_[static_cast<std::size_t>(n)];
  const std::string p = c.header.substr(5);  // after "CHAN:"
  auto answer = [&](auto value) { reply += fmt::format("{}{}", value, mcs2::kEol); };
  // A set command's one value, an integer within [lo, hi] (decimals rounded where `rounded`).
  auto value = [&](std::int64_t lo, std::int64_t hi, bool rounded = false) -> std::optional<std::int64_t> {
    if (c.args.empty()) return push_error(mcs2::kMissingParameter), std::nullopt;
    if (c.args.size() > 1) return push_error(mcs2::kParameterNotAllowed), std::nullopt;
    const auto v = rounded ? mcs2::parse_rounded(c.args[0]) : mcs2::parse_integer(c.args[0]);
    if (!v) return push_error(mcs2::kDataTypeError), std::nullopt;
    if (*v < lo || *v > hi) return push_error(mcs2::kDataOutOfRange), std::nullopt;
    return v;
  };
  auto sensor_readable = [&] {
    if (!ch.sensor_present) return push_error(mcs2::kNoSensorPresent), false;
    if (ch.sensor_mode == mcs2::kSensorOff) return push_error(mcs2::kSensorDisabled), false;
    return true;
  };
  auto position = [&] { return stage_units(n) + ch.offset; };
  // The properties that read and set one integer member.
  struct Plain {
    const char* name;
    int Mcs2Channel::*member;
    std::int64_t lo, hi;
  };
  static constexpr Plain kPlain[] = {
      {"STEP:FREQ", &Mcs2Channel::step_frequency_Hz, 1, mcs2::kMaxStepFrequency_Hz},
      {"STEP:AMPL", &Mcs2Channel::step_amplitude, 1, mcs2::kFullAmplitude},
      {"MCLF", &Mcs2Channel::mclf_Hz, 50, mcs2::kMaxStepFrequency_Hz},
      {"MCLF:CURR", &Mcs2Channel::mclf_Hz, 50, mcs2::kMaxStepFrequency_Hz},
      {"REF:OPT", &Mcs2Channel::ref_options, 0, mcs2::kRefOptMask},
      {"SDIR", &Mcs2Channel::safe_direction, 0, 1},
  };
  for (const Plain& q : kPlain) {
    if (p != q.name) continue;
    if (c.query) return answer(ch.*q.member);
    if (const auto v = value(q.lo, q.hi)) ch.*q.member = static_cast<int>(*v);
    return;
  }
  if (p == "MMOD") {
    if (c.query) return answer(ch.move_mode);
    if (const auto v = value(mcs2::kAbsolute, mcs2::kStep)) ch.move_mode = static_cast<int>(*v);
    return;
  }
  if (p == "VEL" || p == "ACC") {
    std::int64_t& m = p == "VEL" ? ch.velocity : ch.acceleration;
    if (c.query) return answer(m);
    if (const auto v = value(0, 100'000'000'000'000, true)) m = *v;
    return;
  }
  if (p == "HOLD") {
    if (c.query) return answer(ch.hold_ms);
    // -1 holds forever; so does 4294967295, the same 32 bits written unsigned.
    if (c.args.size() == 1 && c.args[0] == "4294967295") return void(ch.hold_ms = -1);
    if (const auto v = value(-1, 60'000)) ch.hold_ms = *v;
    return;
  }
  if (p == "POS" || p == "POS:CURR") {
    if (!sensor_readable()) return;
    if (c.query) return answer(position());
    // Sets the present position: the scale shifts, the target with it.
    if (const auto v = value(-1'000'000'000'000'000'000, 1'000'000'000'000'000'000, true)) {
      const std::int64_t shift = *v - position();
      ch.offset += shift;
      ch.target += shift;
    }
    return;
  }
  if (p == "POS:TARG" && c.query) {
    if (!sensor_readable()) return;
    return answer(ch.closed_loop ? ch.target : position());
  }
  if (p == "SENS:MODE") {
    if (c.query) return answer(ch.sensor_mode);
    const auto v = value(mcs2::kSensorOff, mcs2::kSensorPowerSave);
    if (!v) return;
    if (*v != mcs2::kSensorOff && !ch.sensor_present) return push_error(mcs2::kNoSensorPresent);
    if (*v == mcs2::kSensorOff && !may_stop(client)) return push_error(mcs2::kPermissionDenied);
    // Without its sensor the channel cannot hold a target: it stops and holds where it is.
    if (*v == mcs2::kSensorOff && ch.closed_loop) {
      stop(client, n);
      ch.closed_loop = false;
    }
    ch.sensor_mode = static_cast<int>(*v);
    return;
  }
  if (p == "AMPL") {
    if (c.query) return answer(ch.amplifier ? 1 : 0);
    const auto v = value(0, 1);
    if (!v) return;
    if (*v == 0 && !may_stop(client)) return push_error(mcs2::kPermissionDenied);
    if (*v == 0 && ch.amplifier) {
      stop(client, n);  // no drive: it stops
      ch.closed_loop = false;
    }
    ch.amplifier = *v == 1;
    return;
  }
  if (p == "PTYP" || p == "PTYP:CODE") {
    if (c.query) return answer(ch.positioner_type);
    const auto v = value(0, 500);
    if (!v) return;
    // Another positioner: it must be calibrated and referenced again (README.SmarActMCS2).
    ch.positioner_type = static_cast<int>(*v);
    ch.calibrated = ch.referenced = false;
    return;
  }
  if (!c.query) return push_error(mcs2::kUndefinedHeader);  // the rest are read-only
  if (p == "STAT") return answer(state(n));
  if (p == "PTYP:NAME") return answer(fmt::format("\"{}\"", positioner_name(ch.positioner_type)));
  if (p == "TUN:BASE:UNIT") return answer(rotary(n) ? mcs2::kUnitDegree : mcs2::kUnitMeter);
  if (p == "TUN:BASE:RES") return answer(rotary(n) ? mcs2::kResolutionRotary : mcs2::kResolutionLinear);
  if (p == "RLIM:MIN") return answer(min_units(n));
  if (p == "RLIM:MAX") return answer(max_units(n));
  if (p == "TEMP") return answer("25.0");
  if (p == "ERR") return answer(0);
  if (p == "FERR") {
    if (!sensor_readable()) return;
    return answer(ch.closed_loop ? std::llabs(ch.target - position()) : 0);
  }
  push_error(mcs2::kUndefinedHeader);
}

}  // namespace mc::twins
