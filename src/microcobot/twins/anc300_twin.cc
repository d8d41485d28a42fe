#include "microcobot/twins/anc300_twin.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "microcobot/core/error.h"

namespace mc::twins {

using drivers::anc300::Mode;
using drivers::anc300::reply_error;
using drivers::anc300::reply_ok;
using drivers::anc300::value_line;

namespace {
constexpr double kDegPerRad = 180.0 / std::numbers::pi;
}  // namespace

void Anc300TwinParams::validate() const {
  require(std::isfinite(frequency_Hz) && frequency_Hz >= 1 && frequency_Hz <= 10e3, "anc300.frequency_Hz",
          "must be within [1, 10000] Hz", frequency_Hz);
  require(std::isfinite(voltage_V) && voltage_V >= 0 && voltage_V <= 100, "anc300.voltage_V",
          "must be within [0, 100] V", voltage_V);
  require(std::isfinite(capacitance_nF) && capacitance_nF > 0, "anc300.capacitance_nF", "must be > 0",
          capacitance_nF);
}

Anc300Twin::Anc300Twin(TwinStage& stage, Anc300TwinParams params)
    : stage_(stage), params_(params), axes_(std::clamp(stage.axis_count(), 3, TwinStage::kMaxAxes)) {
  params_.validate();
  mode_.fill(Mode::kGnd);  // a controller powers up with its axes grounded
  frequency_Hz_.fill(std::round(params_.frequency_Hz));
  voltage_V_.fill(std::min(params_.voltage_V, stage_.max_voltage_V()));
}

int Anc300Twin::axis_index(std::string_view id) const {
  if (id.size() != 1 || id[0] < '1' || id[0] >= '1' + axes_) return -1;
  return id[0] - '1';
}

std::string Anc300Twin::greeting() const {
  return std::string("attocube ANC300 console (microcobot digital twin)") +
         std::string(drivers::anc300::kEol) + std::string(drivers::anc300::kPasswordPrompt);
}

std::string Anc300Twin::on_password(Anc300Session& s, std::string_view /*line*/, bool accepted) {
  s.authorized = accepted;
  std::string out(drivers::anc300::kEol);
  out += accepted ? drivers::anc300::kAuthorized : drivers::anc300::kNotAuthorized;
  out += drivers::anc300::kEol;
  if (accepted && s.echo) out += drivers::anc300::kPrompt;
  if (!accepted) out += drivers::anc300::kPasswordPrompt;  // asked again
  return out;
}

std::string Anc300Twin::finish(const Anc300Session& s, std::string_view echoed,
                               const std::string& body) const {
  if (!s.echo) return body;
  std::string out(echoed);
  out += drivers::anc300::kEol;
  out += body;
  out += drivers::anc300::kPrompt;
  return out;
}

std::string Anc300Twin::on_overlong_line(const Anc300Session& s) const {
  return finish(
      s, "", reply_error(fmt::format("Command longer than {} characters", drivers::anc300::kMaxLineLength)));
}

std::string Anc300Twin::refusal(TwinStage::Refusal r) const {
  switch (r) {
    case TwinStage::Refusal::kHalted:
      return reply_error("Platform halted (emergency stop latched)");
    case TwinStage::Refusal::kOtherOperator:
      return reply_error("Another operator controls the stage");
    case TwinStage::Refusal::kBusy:
      return reply_error("Controller busy, try again");
    case TwinStage::Refusal::kUnreachable:
      return reply_error("Out of range");
    case TwinStage::Refusal::kNone:
      break;
  }
  return reply_ok();
}

std::optional<std::string> Anc300Twin::on_line(ClientId client, Anc300Session& s, std::string_view line) {
  while (!line.empty() && (line.back() == '\r' || line.back() == '\n')) line.remove_suffix(1);
  const auto r = drivers::anc300::parse_line(line);
  if (!r) return finish(s, line, "");
  waiting_axis_ = -1;
  if (r->command == "echo") {
    if (r->args.size() != 1 || (r->args[0] != "on" && r->args[0] != "off"))
      return finish(s, line, reply_error("Usage: echo on|off"));
    const Anc300Session before = s;
    s.echo = r->args[0] == "on";
    // The line that turned echo off was still echoed; the prompt follows the new setting.
    std::string out = before.echo ? std::string(line) + std::string(drivers::anc300::kEol) : std::string();
    out += reply_ok();
    if (s.echo) out += drivers::anc300::kPrompt;
    return out;
  }
  if (r->command == "stepw") {
    const int axis = r->args.size() == 1 ? axis_index(r->args[0]) : -1;
    if (axis < 0) return finish(s, line, reply_error("Invalid axis"));
    if (stage_.axis(axis).stepping) {
      waiting_axis_ = axis;
      pending_echo_ = std::string(line);
      return std::nullopt;
    }
    return finish(s, line, reply_ok());
  }
  return finish(s, line, execute(client, *r));
}

std::optional<std::string> Anc300Twin::poll_wait(Anc300Session& s, int axis) {
  if (axis < 0 || axis >= axes_ || stage_.axis(axis).stepping) return std::nullopt;
  return finish(s, pending_echo_, reply_ok());
}

std::string Anc300Twin::execute(ClientId client, const drivers::anc300::Request& r) {
  const std::string& c = r.command;
  if (c == "ver") return reply_ok({"attocube ANC300 controller, microcobot digital twin 1.0"});
  if (c == "getcser") return reply_ok({"ANC300-TWIN"});
  if (c == "help") {
    return reply_ok(
        {"echo on|off", "ver", "getcser", "getser N", "setm N gnd|stp|cap|off", "getm N", "setf N Hz",
         "getf N", "setv N V", "getv N", "stepu N [n]", "stepd N [n]", "stepw N", "stop N", "getc N",
         "capw N", "getpos N (twin only: the sensor)",
         axes_ > TwinStage::kTheta ? "axes: 1 2 3 (X, Y, Z), 4 (theta, rotary)" : "axes: 1 2 3 (X, Y, Z)"});
  }
  // Every other command names an axis.
  if (r.args.empty()) return reply_error("Missing axis");
  const int axis = axis_index(r.args[0]);
  if (axis < 0)
    return reply_error(fmt::format("Invalid axis '{}' (axes 1 to {})", r.args[0].substr(0, 16), axes_));
  const auto k = static_cast<std::size_t>(axis);
  const std::size_t nargs = r.args.size() - 1;
  auto one_value = [&]() -> std::optional<double> {
    if (nargs != 1) return std::nullopt;
    return drivers::anc300::parse_number(r.args[1]);
  };
  if (c == "getser") return reply_ok({value_line("serial number", fmt::format("TWIN-AXIS-{}", axis + 1))});
  if (c == "getm") return reply_ok({value_line("mode", drivers::anc300::mode_name(mode_[k]))});
  if (c == "getf") return reply_ok({value_line("frequency", fmt::format("{:.0f}", frequency_Hz_[k]), "Hz")});
  if (c == "getv") return reply_ok({value_line("voltage", fmt::format("{:.6f}", voltage_V_[k]), "V")});
  if (c == "getc")
    return reply_ok({value_line("capacitance", fmt::format("{:.1f}", params_.capacitance_nF), "nF")});
  if (c == "capw") return reply_ok();
  if (c == "getpos") {
    // The rotary positioner's angle in degrees, as attocube's rotators are read; the linear axes' in m.
    if (axis == TwinStage::kTheta)
      return reply_ok(
          {value_line("position", fmt::format("{:.9e}", stage_.axis(axis).position * kDegPerRad), "deg")});
    return reply_ok({value_line("position", fmt::format("{:.9e}", stage_.axis(axis).position), "m")});
  }
  if (c == "setm") {
    const auto m = nargs == 1 ? drivers::anc300::parse_mode(r.args[1]) : std::nullopt;
    if (!m) return reply_error("Usage: setm N gnd|inp|cap|stp|off|stp+|stp-");
    if (*m != Mode::kGnd && *m != Mode::kStp && *m != Mode::kCap && *m != Mode::kOff)
      return reply_error("Mode not available on this axis (the twin's axes: gnd, stp, cap, off)");
    if (*m != Mode::kStp && stage_.axis(axis).stepping) stage_.stop(client);  // grounding stops the output
    mode_[k] = *m == Mode::kCap ? Mode::kGnd : *m;  // the capacitance "measurement" is instant
    return reply_ok();
  }
  if (c == "setf") {
    const auto v = one_value();
    if (!v || *v < 1.0 || *v > 10e3) return reply_error("Value out of range (frequency: 1 to 10000 Hz)");
    frequency_Hz_[k] = std::round(*v);
    return reply_ok();
  }
  if (c == "setv") {
    const auto v = one_value();
    if (!v || *v < 0.0 || *v > stage_.max_voltage_V())
      return reply_error(
          fmt::format("Value out of range (voltage: 0 to {:g} V, the amplifier's)", stage_.max_voltage_V()));
    voltage_V_[k] = *v;
    return reply_ok();
  }
  if (c == "stop") {
    stage_.stop(client);
    return reply_ok();
  }
  if (c == "stepu" || c == "stepd") {
    long long n = 1;
    if (nargs == 1) {
      const auto count = drivers::anc300::parse_count(r.args[1]);
      if (!count) return reply_error("Value out of range (steps: a whole number)");
      n = *count;
    } else if (nargs > 1) {
      return reply_error("Usage: " + c + " N [steps]");
    }
    if (n == 0 || n > 1'000'000'000)
      return reply_error("Value out of range (steps: 1 to 1e9; continuous stepping is not emulated)");
    if (mode_[k] != Mode::kStp) return reply_error("Axis not in stepping mode (setm N stp)");
    if (voltage_V_[k] <= 0.0) return reply_error("Voltage is 0 V (setv N V)");
    return refusal(stage_.step(client, axis, voltage_V_[k], frequency_Hz_[k], c == "stepu" ? +1 : -1, n));
  }
  return reply_error("Unknown command '" + c.substr(0, 32) + "'");
}

}  // namespace mc::twins
