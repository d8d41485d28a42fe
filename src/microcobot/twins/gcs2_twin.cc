#include "microcobot/twins/gcs2_twin.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "microcobot/core/error.h"

namespace mc::twins {

using drivers::gcs2::axis_value;

namespace {
constexpr const char* kAxisNames[TwinStage::kMaxAxes] = {"1", "2", "3", "4"};
/// PUN?'s answers: PI's own spelling, as GCS clients compare it (docs/hardware.md).
constexpr const char* kUnits[TwinStage::kMaxAxes] = {"mm", "mm", "mm", "deg"};
}  // namespace

void Gcs2TwinParams::validate() const {
  require(address >= 1 && address <= 254, "gcs2.address", "must be within [1, 254]", address);
  require(std::isfinite(velocity_mm_s) && velocity_mm_s > 0, "gcs2.velocity_mm_s", "must be > 0",
          velocity_mm_s);
  require(std::isfinite(velocity_deg_s) && velocity_deg_s > 0, "gcs2.velocity_deg_s", "must be > 0",
          velocity_deg_s);
  require(!idn.empty() && idn.size() < 200 && idn.find('\n') == std::string::npos, "gcs2.idn",
          "must be one line of fewer than 200 characters");
}

Gcs2Twin::Gcs2Twin(TwinStage& stage, Gcs2TwinParams params)
    : stage_(stage),
      params_(std::move(params)),
      axes_(std::clamp(stage.axis_count(), 3, TwinStage::kMaxAxes)) {
  params_.validate();
  for (int i = 0; i < axes_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double v = i == TwinStage::kTheta ? params_.velocity_deg_s : params_.velocity_mm_s;
    velocity_[k] = std::min(v, stage_.max_speed(i) * per_si(i));
    target_[k] = position(i);
  }
}

double Gcs2Twin::per_si(int i) {
  return i == TwinStage::kTheta ? drivers::gcs2::kDegPerRad : drivers::gcs2::kMmPerM;
}

int Gcs2Twin::axis_index(std::string_view word) const {
  for (int i = 0; i < axes_; ++i)
    if (word == kAxisNames[i]) return i;
  return -1;
}

std::vector<int> Gcs2Twin::all_axes() const {
  std::vector<int> axes;
  for (int i = 0; i < axes_; ++i) axes.push_back(i);
  return axes;
}

bool Gcs2Twin::query_axes(const std::vector<std::string>& args, std::vector<int>& axes) {
  axes.clear();
  if (args.empty() || (args.size() == 1 && (args[0] == "ALL" || args[0] == "all"))) {
    axes = all_axes();
    return true;
  }
  for (const auto& a : args) {
    const int i = axis_index(a);
    if (i < 0) {
      set_error(drivers::gcs2::kInvalidAxis);
      return false;
    }
    axes.push_back(i);
  }
  return true;
}

bool Gcs2Twin::pairs(const std::vector<std::string>& args, std::vector<std::pair<int, double>>& out) {
  out.clear();
  if (args.empty() || args.size() % 2 != 0) {
    set_error(drivers::gcs2::kParameterSyntax);
    return false;
  }
  for (std::size_t k = 0; k < args.size(); k += 2) {
    const int i = axis_index(args[k]);
    if (i < 0) {
      set_error(drivers::gcs2::kInvalidAxis);
      return false;
    }
    const auto v = drivers::gcs2::parse_number(args[k + 1]);
    if (!v) {
      set_error(drivers::gcs2::kParameterSyntax);
      return false;
    }
    out.emplace_back(i, *v);
  }
  return true;
}

void Gcs2Twin::update_referencing() {
  for (int i = 0; i < axes_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (referencing_[k] && stage_.axis(i).on_target) {
      referencing_[k] = false;
      referenced_[k] = true;
    }
  }
}

bool Gcs2Twin::send_goal(ClientId client, unsigned moved) {
  TwinStage::Goal goal{};
  double speed = 1e9, slowest = 1e9;
  for (int i = 0; i < axes_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    // An axis with its servo off is not commanded: it holds where it is.
    goal[k] = servo_[k] ? target_[k] / per_si(i) : stage_.axis(i).position;
    if (i == TwinStage::kTheta) continue;
    slowest = std::min(slowest, velocity_[k] / drivers::gcs2::kMmPerM);
    if (moved & (1u << i)) speed = std::min(speed, velocity_[k] / drivers::gcs2::kMmPerM);
  }
  // A move of the rotation stage alone leaves the linear axes at the slowest pace they may be
  // travelling at.
  if (speed == 1e9) speed = slowest;
  const double theta_speed = velocity_[TwinStage::kTheta] / drivers::gcs2::kDegPerRad;
  switch (stage_.move_to(client, goal, speed, theta_speed)) {
    case TwinStage::Refusal::kNone:
      return true;
    case TwinStage::Refusal::kHalted:
    case TwinStage::Refusal::kOtherOperator:
    case TwinStage::Refusal::kBusy:
    case TwinStage::Refusal::kUnreachable:
      set_error(drivers::gcs2::kStopped);
      return false;
  }
  return false;
}

void Gcs2Twin::stop_all(ClientId client) {
  stage_.stop(client);
  for (int i = 0; i < axes_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    target_[k] = position(i);
    referencing_[k] = false;
  }
  set_error(drivers::gcs2::kStopped);
}

std::string Gcs2Twin::on_byte(ClientId client, char byte) {
  update_referencing();
  if (byte == drivers::gcs2::kMotionStatus) {
    unsigned mask = 0;
    for (int i = 0; i < axes_; ++i) {
      const auto a = stage_.axis(i);
      if (a.stepping || (servo_[static_cast<std::size_t>(i)] && !a.on_target)) mask |= 1u << i;
    }
    return fmt::format("{:X}\n", mask);
  }
  if (byte == drivers::gcs2::kReadyStatus) {
    const bool busy = std::any_of(referencing_.begin(), referencing_.end(), [](bool b) { return b; });
    return std::string(1, static_cast<char>(busy ? drivers::gcs2::kBusy : drivers::gcs2::kReady)) + "\n";
  }
  if (byte == drivers::gcs2::kStopAll) stop_all(client);
  return "";
}

std::string Gcs2Twin::on_line(ClientId client, std::string_view line) {
  const auto r = drivers::gcs2::parse_line(line);
  if (!r) return "";
  if (r->target_address != 0 && r->target_address != params_.address) return "";  // another controller's
  update_referencing();
  Lines reply;
  if (!execute(client, *r, reply) || reply.empty()) return "";
  return drivers::gcs2::format_reply(reply, r->target_address);
}

bool Gcs2Twin::execute(ClientId client, const drivers::gcs2::Request& r, Lines& reply) {
  const std::string& m = r.mnemonic;
  std::vector<int> axes;
  std::vector<std::pair<int, double>> values;
  auto per_axis = [&](auto&& value_of) {
    if (!query_axes(r.args, axes)) return false;
    for (int i : axes) reply.push_back(value_of(i));
    return true;
  };
  if (m == "*IDN?") {
    reply.push_back(params_.idn);
  } else if (m == "CSV?") {
    reply.push_back("2.0");
  } else if (m == "HLP?") {
    for (const char* h : {"The following commands are valid:",
                          "*IDN? Get Device Identification",
                          "CSV? Get Current Syntax Version",
                          "ERR? Get Error Number",
                          "FRF [{<AxisID>}] Fast Reference Move To Reference Switch",
                          "FRF? [{<AxisID>}] Get Referencing Result",
                          "HLP? Get List Of Available Commands",
                          "HLT [{<AxisID>}] Halt Motion Smoothly",
                          "MOV {<AxisID> <Position>} Set Target Position",
                          "MOV? [{<AxisID>}] Get Target Position",
                          "MVR {<AxisID> <Distance>} Set Target Relative To Current Target",
                          "ONT? [{<AxisID>}] Get On Target State",
                          "POS? [{<AxisID>}] Get Real Position",
                          "PUN? [{<AxisID>}] Get Position Unit",
                          "SAI? [ALL] Get List Of Current Axis Identifiers",
                          "STP Stop All Axes",
                          "SVO {<AxisID> <ServoState>} Set Servo Mode",
                          "SVO? [{<AxisID>}] Get Servo Mode",
                          "TMN? [{<AxisID>}] Get Minimum Commandable Position",
                          "TMX? [{<AxisID>}] Get Maximum Commandable Position",
                          "VEL {<AxisID> <Velocity>} Set Closed-Loop Velocity",
                          "VEL? [{<AxisID>}] Get Closed-Loop Velocity",
                          "#5 Request Motion Status",
                          "#7 Request Controller Ready Status",
                          "#24 Stop All Axes",
                          "end of help"})
      reply.emplace_back(h);
  } else if (m == "SAI?") {
    if (!r.args.empty() && !(r.args.size() == 1 && (r.args[0] == "ALL" || r.args[0] == "all"))) {
      set_error(drivers::gcs2::kParameterSyntax);
      return false;
    }
    for (int i = 0; i < axes_; ++i) reply.emplace_back(kAxisNames[i]);
  } else if (m == "ERR?") {
    reply.push_back(std::to_string(error_));
    error_ = drivers::gcs2::kNoError;
  } else if (m == "POS?") {
    return per_axis([&](int i) { return axis_value(kAxisNames[i], position(i)); });
  } else if (m == "PUN?") {
    return per_axis([&](int i) { return std::string(kAxisNames[i]) + "=" + kUnits[i]; });
  } else if (m == "MOV?") {
    return per_axis([&](int i) { return axis_value(kAxisNames[i], target_[static_cast<std::size_t>(i)]); });
  } else if (m == "ONT?") {
    return per_axis([&](int i) { return axis_value(kAxisNames[i], stage_.axis(i).on_target ? 1 : 0); });
  } else if (m == "SVO?") {
    return per_axis(
        [&](int i) { return axis_value(kAxisNames[i], servo_[static_cast<std::size_t>(i)] ? 1 : 0); });
  } else if (m == "FRF?") {
    return per_axis(
        [&](int i) { return axis_value(kAxisNames[i], referenced_[static_cast<std::size_t>(i)] ? 1 : 0); });
  } else if (m == "VEL?") {
    return per_axis([&](int i) { return axis_value(kAxisNames[i], velocity_[static_cast<std::size_t>(i)]); });
  } else if (m == "TMN?") {
    return per_axis([&](int i) { return axis_value(kAxisNames[i], stage_.min(i) * per_si(i)); });
  } else if (m == "TMX?") {
    return per_axis([&](int i) { return axis_value(kAxisNames[i], stage_.max(i) * per_si(i)); });
  } else if (m == "SVO") {
    if (!pairs(r.args, values)) return false;
    for (auto [i, v] : values)
      if (v != 0.0 && v != 1.0) return set_error(drivers::gcs2::kParameterOutOfRange), false;
    for (auto [i, v] : values) {
      const auto k = static_cast<std::size_t>(i);
      // Servo on: the target becomes the present position (as the controller's does).
      if (v == 1.0 && !servo_[k]) target_[k] = position(i);
      servo_[k] = v == 1.0;
      if (!servo_[k]) referencing_[k] = false;
    }
  } else if (m == "VEL") {
    if (!pairs(r.args, values)) return false;
    for (auto [i, v] : values)
      if (!(v > 0.0 && v <= stage_.max_speed(i) * per_si(i)))
        return set_error(drivers::gcs2::kParameterOutOfRange), false;
    for (auto [i, v] : values) velocity_[static_cast<std::size_t>(i)] = v;
  } else if (m == "MOV" || m == "MVR") {
    if (!pairs(r.args, values)) return false;
    if (stage_.halted()) return set_error(drivers::gcs2::kStopped), false;
    auto target = target_;
    for (auto [i, v] : values) {
      const auto k = static_cast<std::size_t>(i);
      if (!servo_[k] || !referenced_[k]) return set_error(drivers::gcs2::kUnallowableMove), false;
      target[k] = m == "MOV" ? v : target_[k] + v;
      // Every named axis is checked before any is moved: nothing of a refused line is applied.
      if (target[k] < stage_.min(i) * per_si(i) - 1e-9 || target[k] > stage_.max(i) * per_si(i) + 1e-9)
        return set_error(drivers::gcs2::kPositionOutOfLimits), false;
    }
    unsigned moved = 0;
    for (auto [i, v] : values) moved |= 1u << i;
    const auto before = target_;
    target_ = target;
    if (!send_goal(client, moved)) target_ = before;
  } else if (m == "FRF") {
    if (!query_axes(r.args, axes)) return false;
    if (stage_.halted()) return set_error(drivers::gcs2::kStopped), false;
    for (int i : axes)
      if (!servo_[static_cast<std::size_t>(i)]) return set_error(drivers::gcs2::kUnallowableMove), false;
    // The reference position is the stage's home (0 mm, 0 deg): a closed-loop move there.
    const auto before = target_;
    unsigned moved = 0;
    for (int i : axes) {
      target_[static_cast<std::size_t>(i)] = 0.0;
      moved |= 1u << i;
    }
    if (!send_goal(client, moved)) {
      target_ = before;
      return false;
    }
    for (int i : axes) {
      referencing_[static_cast<std::size_t>(i)] = true;
      referenced_[static_cast<std::size_t>(i)] = false;
    }
  } else if (m == "HLT" || m == "STP") {
    if (m == "HLT" && !query_axes(r.args, axes)) return false;
    stop_all(client);  // the stage's axes move as one (one goal): halting one halts them all
  } else {
    set_error(drivers::gcs2::kUnknownCommand);
    return false;
  }
  return true;
}

}  // namespace mc::twins
