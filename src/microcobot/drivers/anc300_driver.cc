#include "microcobot/drivers/anc300_driver.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "microcobot/drivers/anc300_codec.h"
#include "microcobot/drivers/sim_companions.h"

namespace mc::drivers {
namespace {

constexpr const char* kEol = "\r\n";

}  // namespace

void Anc300DriverParams::validate() const {
  timing.validate();
  require(!password.empty() && password.size() <= 256 && password.find_first_of("\r\n,") == std::string::npos,
          "devices.connection option password", "must be 1 to 256 characters, one line, no ','");
  for (int a : axes)
    require(a >= 1 && a <= 7, "devices.connection option axes", "each axis must be within 1..7",
            static_cast<double>(a));
  require(axes[0] != axes[1] && axes[1] != axes[2] && axes[0] != axes[2], "devices.connection option axes",
          "must name three different axes");
  require(
      theta == 0 || (theta >= 1 && theta <= 7 && theta != axes[0] && theta != axes[1] && theta != axes[2]),
      "devices.connection option theta", "must be an axis within 1..7 other than X's, Y's and Z's", theta);
  require(std::isfinite(radius_m) && radius_m > 0, "stage.rotary.radius_m", "must be > 0", radius_m);
  step.validate("ANC300", 150.0, 10e3);
}

Anc300DriverParams anc300_driver_params(const Connection& c) {
  check_connection_options(c, std::string(kBusTimingOptions) + ", password, axes, theta, position, " +
                                  std::string(kStepDriveOptions));
  Anc300DriverParams p;
  p.timing = bus_timing(c, p.timing);
  p.step = step_drive_options(c, p.step, 150.0, 10e3);
  if (const auto it = c.options.find("password"); it != c.options.end()) p.password = it->second;
  if (const auto it = c.options.find("position"); it != c.options.end()) {
    if (it->second != "counted" && it->second != "getpos")
      throw InvalidParams("devices.connection option position",
                          "'" + excerpt(it->second) + "' must be counted or getpos (the twin's sensor)");
    p.sensor = it->second == "getpos";
  }
  if (const auto it = c.options.find("axes"); it != c.options.end()) {
    const std::string& v = it->second;
    if (v.size() != 5 || v[1] != '+' || v[3] != '+' || !std::isdigit(static_cast<unsigned char>(v[0])) ||
        !std::isdigit(static_cast<unsigned char>(v[2])) || !std::isdigit(static_cast<unsigned char>(v[4])))
      throw InvalidParams("devices.connection option axes",
                          "'" + excerpt(v) + "' must be three axis numbers joined by '+' (e.g. 1+2+3)");
    p.axes = {v[0] - '0', v[2] - '0', v[4] - '0'};
  }
  p.theta = static_cast<int>(connection_number(c, "theta", 0.0, 1.0, 7.0));
  if (c.options.count("theta") && std::to_string(p.theta) != c.options.at("theta"))
    throw InvalidParams("devices.connection option theta",
                        "'" + excerpt(c.options.at("theta")) + "' must be an axis number within 1..7");
  return p;  // validated once the steps are known (make_anc300_devices)
}

Anc300Controller::Anc300Controller(Connection connection, Anc300DriverParams params)
    : BusController("anc300", std::move(connection), params.timing), params_(std::move(params)) {
  params_.validate();
}

std::vector<std::string> Anc300Controller::request(LineClient& bus, const std::string& line,
                                                   double timeout_s) {
  const auto deadline = timeout_s > 0.0 ? deadline_in(timeout_s) : reply_deadline();
  if (!bus.send(line + kEol, deadline)) throw BusFault("'" + line + "': " + bus.error());
  std::string reply;
  bool ok = false;
  if (!bus.read_until(
          reply, [&ok](const std::string& t) { return anc300::reply_end(t, &ok); }, deadline)) {
    std::string got = reply.empty() ? std::string() : " (got '" + excerpt(reply, 60) + "')";
    throw BusFault("'" + line + "': " + bus.error() + got);
  }
  auto lines = anc300::reply_lines(reply);
  if (!ok)
    throw BusFault("'" + line + "': ERROR (" +
                   excerpt(lines.empty() ? std::string("no message") : lines.back()) + ")");
  return lines;
}

double Anc300Controller::read_position(LineClient& bus, int i) {
  const auto k = static_cast<std::size_t>(i);
  const std::string line = fmt::format("getpos {}", axis_id(k));
  const auto lines = request(bus, line);
  // The linear axes' in m; the rotary positioner's in deg, turned into the arc at the radius.
  const std::string_view unit = k < 3 ? " m" : " deg";
  const bool unit_ok = lines.size() == 1 && std::string_view(lines[0]).ends_with(unit);
  const auto value = unit_ok ? anc300::value_of(lines[0]) : std::nullopt;
  const auto v = value ? anc300::parse_number(*value) : std::nullopt;
  if (!v)
    throw BusFault(fmt::format("'{}': expected 'position = VALUE{}', got '{}'", line, unit,
                               excerpt(lines.empty() ? "" : lines[0])));
  return k < 3 ? *v : *v * std::numbers::pi / 180.0 * params_.radius_m;
}

void Anc300Controller::handshake(LineClient& bus) {
  const double login_s = timing().connect_timeout_s;
  std::string text;
  auto has = [](std::string_view what) {
    return [what](const std::string& t) -> std::size_t {
      const auto at = t.find(what);
      return at == std::string::npos ? 0 : at + what.size();
    };
  };
  // The password prompt is the telnet console's; the serial (USB/RS-232) console has none, and
  // the line may hold what a previous session left: dropped before the first command.
  if (connection().is_serial()) {
    bus.discard_input();
  } else {
    if (!bus.read_until(text, has("Authorization code"), deadline_in(login_s)))
      throw BusFault("no password prompt ('Authorization code:'): " + bus.error() +
                     (text.empty() ? std::string() : " (got '" + excerpt(text, 60) + "')"));
    bus.discard_input();
    if (!bus.send(params_.password + kEol, deadline_in(login_s))) throw BusFault("password: " + bus.error());
    text.clear();
    const auto verdict = [](const std::string& t) -> std::size_t {
      for (std::string_view w : {anc300::kAuthorized, anc300::kNotAuthorized}) {
        const auto at = t.find(w);
        if (at != std::string::npos) {
          const auto eol = t.find('\n', at);
          if (eol != std::string::npos) return eol + 1;
        }
      }
      return 0;
    };
    if (!bus.read_until(text, verdict, deadline_in(login_s))) throw BusFault("password: " + bus.error());
    if (text.find(anc300::kAuthorized) == std::string::npos)
      throw BusFault("the controller refused the password (Authorization failed; option password=...)");
  }
  request(bus, "echo off", login_s);
  const auto ver = request(bus, "ver");
  set_identity(ver.empty() ? std::string("ANC300") : ver[0]);
  const auto count = static_cast<std::size_t>(axis_count());
  for (std::size_t i = 0; i < count; ++i) {
    const int a = axis_id(i);
    try {
      request(bus, fmt::format("getser {}", a));
    } catch (const BusFault& e) {
      throw BusFault(fmt::format("axis {} is not there: {}", a, e.what()));
    }
    request(bus, fmt::format("setm {} stp", a));
    request(bus, fmt::format("setf {} {:.0f}", a, params_.step.frequency_Hz));
    request(bus, fmt::format("setv {} {:.3f}", a, params_.step.voltage_V));
    stepping_mode_[i] = true;
    if (params_.sensor) est_m_[i] = read_position(bus, static_cast<int>(i));
    publish_position(static_cast<int>(i), est_m_[i]);
  }
  publish_stamp();
}

void Anc300Controller::cycle(LineClient& bus) {
  const Targets t = targets();
  const int count = axis_count();
  if (params_.sensor)
    for (int i = 0; i < count; ++i) {
      est_m_[static_cast<std::size_t>(i)] = read_position(bus, i);
      publish_position(i, est_m_[static_cast<std::size_t>(i)]);
    }
  // Every axis off its target starts its run, then each is waited for: the ANC300 plays its
  // axes' runs at once, so a diagonal move goes at each axis's own speed.
  std::array<long long, kMaxAxes> run{};  // periods started this cycle, signed
  for (std::size_t i = 0; i < static_cast<std::size_t>(count); ++i) {
    if (!t.wanted[i]) continue;
    if (!stepping_mode_[i]) {
      request(bus, fmt::format("setm {} stp", axis_id(i)));  // armed again after a safe state
      stepping_mode_[i] = true;
    }
    const long long n = params_.step.periods_toward(t.m[i] - est_m_[i]);
    if (n == 0) continue;
    request(bus, fmt::format("{} {} {}", n > 0 ? "stepu" : "stepd", axis_id(i), std::abs(n)));
    run[i] = n;
  }
  for (std::size_t i = 0; i < static_cast<std::size_t>(count); ++i) {
    const long long n = run[i];
    if (n == 0) continue;
    // stepw answers once the run is over: n periods, then the reply's own time.
    request(bus, fmt::format("stepw {}", axis_id(i)),
            static_cast<double>(std::abs(n)) / params_.step.frequency_Hz + timing().reply_timeout_s);
    periods_[i].fetch_add(n);
    if (params_.sensor) {
      est_m_[i] = read_position(bus, static_cast<int>(i));
    } else {
      est_m_[i] += params_.step.displacement_m(n);
    }
    publish_position(static_cast<int>(i), est_m_[i]);
  }
  publish_stamp();
}

void Anc300Controller::safe_state(LineClient& bus) {
  for (std::size_t i = 0; i < static_cast<std::size_t>(axis_count()); ++i) {
    request(bus, fmt::format("stop {}", axis_id(i)));
    request(bus, fmt::format("setm {} gnd", axis_id(i)));
    stepping_mode_[i] = false;
  }
}

devices::DeviceSet make_anc300_devices(const platform::PlatformConfig& config) {
  const Connection c = parse_connection(config.devices.connection, "anc300", kAnc300DefaultBaud);
  Anc300DriverParams p = anc300_driver_params(c);
  p.radius_m = config.stage.rotary.radius_m;
  if (p.theta != 0 && !config.stage.rotary.enabled)
    throw InvalidParams("devices.connection option theta",
                        "needs the rotary axis (stage.rotary.enabled: true)");
  const stickslip::StickSlipParams axis = platform::axis_params(config);
  steps_from_model(p.step, axis);  // the step of one period from the model identified for these axes
  spdlog::info("anc300 driver: {:.1f} nm up, {:.1f} nm down per period at {:g} V, {:g} Hz",
               1e9 * p.step.step_up_m, 1e9 * p.step.step_down_m, p.step.voltage_V, p.step.frequency_Hz);
  auto controller = std::make_shared<Anc300Controller>(c, p);  // validates (a model step of 0 is refused)
  devices::DeviceSet d = make_sim_companions(config);
  const char* names[3] = {"anc300_axis_x", "anc300_axis_y", "anc300_axis_z"};
  for (std::size_t i = 0; i < 3; ++i)
    d.axes[i] = std::make_unique<BusAxis>(names[i], controller, static_cast<int>(i), axis.integrator.dt_s,
                                          axis.drive.max_V);
  if (p.theta != 0)
    d.rotary =
        std::make_unique<BusAxis>("anc300_axis_theta", controller, 3, axis.integrator.dt_s, axis.drive.max_V);
  return d;
}

}  // namespace mc::drivers
