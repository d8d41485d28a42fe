#include "microcobot/drivers/gcs2_driver.h"

#include <algorithm>
#include <cmath>
#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "microcobot/drivers/gcs2_codec.h"
#include "microcobot/drivers/gcs2_exchange.h"
#include "microcobot/drivers/sim_companions.h"

namespace mc::drivers {
namespace {

bool valid_axis_id(const std::string& id) {
  return !id.empty() && id.size() <= 16 && std::all_of(id.begin(), id.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
}

}  // namespace

void Gcs2DriverParams::validate() const {
  timing.validate();
  for (const auto& a : axes)
    require(valid_axis_id(a), "devices.connection option axes",
            "three axis ids of letters, digits or '_' joined by '+', not '" + excerpt(a) + "'");
  require(axes[0] != axes[1] && axes[1] != axes[2] && axes[0] != axes[2], "devices.connection option axes",
          "must name three different axes");
  require(theta.empty() || (valid_axis_id(theta) && theta != axes[0] && theta != axes[1] && theta != axes[2]),
          "devices.connection option theta",
          "an axis id of letters, digits or '_' other than X's, Y's and Z's, not '" + excerpt(theta) + "'");
  require(std::isfinite(radius_m) && radius_m > 0, "stage.rotary.radius_m", "must be > 0", radius_m);
  require(std::isfinite(reference_timeout_s) && reference_timeout_s > 0 && reference_timeout_s <= 600,
          "devices.connection option reference_timeout_s", "must be within (0, 600] s", reference_timeout_s);
  require(std::isfinite(velocity_mm_s) && velocity_mm_s >= 0 && velocity_mm_s <= 1e3,
          "devices.connection option velocity_mm_s", "must be within [0, 1000] mm/s (0: the controller's)",
          velocity_mm_s);
}

Gcs2DriverParams gcs2_driver_params(const Connection& c) {
  check_connection_options(c, std::string(kBusTimingOptions) +
                                  ", axes, theta, reference, "
                                  "reference_timeout_s, velocity_mm_s");
  Gcs2DriverParams p;
  p.timing = bus_timing(c, p.timing);
  p.reference = connection_number(c, "reference", 1.0, 0.0, 1.0) != 0.0;
  p.reference_timeout_s = connection_number(c, "reference_timeout_s", p.reference_timeout_s, 0.01, 600.0);
  p.velocity_mm_s = connection_number(c, "velocity_mm_s", p.velocity_mm_s, 0.0, 1e3);
  if (const auto it = c.options.find("axes"); it != c.options.end()) {
    const std::string& v = it->second;
    const auto a = v.find('+'), b = v.find('+', a == std::string::npos ? a : a + 1);
    if (a == std::string::npos || b == std::string::npos || v.find('+', b + 1) != std::string::npos)
      throw InvalidParams("devices.connection option axes",
                          "'" + excerpt(v) + "' must be three axis ids joined by '+' (e.g. 1+2+3)");
    p.axes = {v.substr(0, a), v.substr(a + 1, b - a - 1), v.substr(b + 1)};
  }
  if (const auto it = c.options.find("theta"); it != c.options.end()) p.theta = it->second;
  p.validate();
  return p;
}

Gcs2Controller::Gcs2Controller(Connection connection, Gcs2DriverParams params)
    : BusController("pi-gcs2", std::move(connection), params.timing), params_(std::move(params)) {
  params_.validate();
}

std::string Gcs2Controller::axis_list() const {
  std::string list = params_.axes[0] + " " + params_.axes[1] + " " + params_.axes[2];
  return params_.theta.empty() ? list : list + " " + params_.theta;
}

double Gcs2Controller::si_per_wire(std::size_t i) const {
  return i < 3 ? 1.0 / gcs2::kMmPerM : params_.radius_m / gcs2::kDegPerRad;
}

std::string Gcs2Controller::query(LineClient& bus, const std::string& line, double timeout_s) {
  return gcs2::query(bus, line, timeout_s > 0.0 ? deadline_in(timeout_s) : reply_deadline());
}

void Gcs2Controller::command(LineClient& bus, const std::string& line, int also_ok) {
  gcs2::command(bus, line, reply_timeout(), gcs2::error_text, also_ok);
}

std::array<double, Gcs2Controller::kMaxAxes> Gcs2Controller::read_axes(LineClient& bus,
                                                                       const std::string& mnemonic) {
  const std::string line = mnemonic + " " + axis_list();
  const std::string reply = query(bus, line);
  std::vector<std::pair<std::string, double>> values;
  try {
    values = gcs2::parse_axis_values(reply);
  } catch (const Error& e) {
    throw BusFault("'" + line + "': " + e.what());
  }
  const auto n = static_cast<std::size_t>(axis_count());
  std::array<double, kMaxAxes> out{};
  std::array<bool, kMaxAxes> seen{};
  for (const auto& [axis, v] : values) {
    for (std::size_t i = 0; i < n; ++i) {
      if (axis == axis_id(i)) {
        out[i] = v;
        seen[i] = true;
      }
    }
  }
  if (values.size() != n || std::count(seen.begin(), seen.begin() + static_cast<std::ptrdiff_t>(n), true) !=
                                static_cast<std::ptrdiff_t>(n))
    throw BusFault("'" + line + "': the reply '" + excerpt(reply, 80) + "' does not give axes " +
                   axis_list());
  return out;
}

void Gcs2Controller::handshake(LineClient& bus) {
  const auto idn = gcs2::reply_lines(query(bus, "*IDN?", timing().connect_timeout_s));
  if (idn.empty() || idn[0].empty()) throw BusFault("*IDN?: an empty identification");
  set_identity(idn[0]);
  const auto csv = gcs2::reply_lines(query(bus, "CSV?"));
  const auto version = csv.size() == 1 ? gcs2::parse_number(csv[0]) : std::nullopt;
  if (!version || *version < 2.0 || *version >= 3.0)
    throw BusFault("CSV? reads '" + excerpt(csv.empty() ? "" : csv[0]) + "': the driver speaks GCS 2.0");
  const auto found = gcs2::reply_lines(query(bus, "SAI? ALL"));
  std::string found_list;
  for (const auto& a : found) found_list += (found_list.empty() ? "" : ", ") + a;
  const auto n = static_cast<std::size_t>(axis_count());
  for (std::size_t i = 0; i < n; ++i)
    if (std::find(found.begin(), found.end(), axis_id(i)) == found.end())
      throw BusFault("SAI? ALL lists axes [" + excerpt(found_list) + "]: no axis '" + axis_id(i) +
                     "' (the configuration wants " + axis_list() + "; options axes=A+B+C, theta=D)");
  if (!params_.theta.empty()) {
    // The rotary axis is a rotation stage: positioned in degrees (PUN?), as the conversion assumes.
    const std::string line = "PUN? " + params_.theta;
    const auto unit = gcs2::reply_lines(query(bus, line));
    if (unit.size() != 1 || unit[0] != params_.theta + "=deg")
      throw BusFault("'" + line + "' reads '" + excerpt(unit.empty() ? "" : unit[0]) +
                     "': the rotary axis must be a rotation stage in deg");
  }
  // A stale error from an earlier session is not this one's.
  gcs2::clear_errors(bus, reply_timeout());
  const auto tmn = read_axes(bus, "TMN?"), tmx = read_axes(bus, "TMX?");
  for (std::size_t i = 0; i < n; ++i) {
    min_m_[i] = tmn[i] * si_per_wire(i);
    max_m_[i] = tmx[i] * si_per_wire(i);
    if (!(min_m_[i] <= 0.0 && max_m_[i] >= 0.0))
      throw BusFault(fmt::format("axis {}: TMN?..TMX? = {}..{} {} does not hold the stage's home (0)",
                                 axis_id(i), tmn[i], tmx[i], i < 3 ? "mm" : "deg"));
  }
  std::string servo = "SVO";
  for (std::size_t i = 0; i < n; ++i) servo += " " + axis_id(i) + " 1";
  command(bus, servo);
  if (params_.velocity_mm_s > 0.0)
    command(bus, fmt::format("VEL {0} {3:.6f} {1} {3:.6f} {2} {3:.6f}", params_.axes[0], params_.axes[1],
                             params_.axes[2], params_.velocity_mm_s));
  const auto vel = read_axes(bus, "VEL?");
  for (std::size_t i = 0; i < 3; ++i)
    if (vel[i] < params_.operator_speed_mm_s)
      spdlog::warn(
          "pi-gcs2: axis {} moves at VEL {:g} mm/s, slower than the operator's {:g} mm/s: the stage will lag "
          "the coupling's target (option velocity_mm_s=1 sets VEL at configure)",
          params_.axes[i], vel[i], params_.operator_speed_mm_s);
  auto referenced = read_axes(bus, "FRF?");
  std::string unreferenced;
  for (std::size_t i = 0; i < n; ++i)
    if (referenced[i] != 1.0) unreferenced += " " + axis_id(i);
  if (!unreferenced.empty()) {
    if (!params_.reference)
      throw BusFault("axes" + unreferenced +
                     " are not referenced (FRF? 0) and the option reference=0 forbids FRF");
    command(bus, "FRF" + unreferenced);
    const auto until = deadline_in(params_.reference_timeout_s);
    while (true) {
      referenced = read_axes(bus, "FRF?");
      if (std::all_of(referenced.begin(), referenced.begin() + static_cast<std::ptrdiff_t>(n),
                      [](double r) { return r == 1.0; }))
        break;
      if (Clock::now() > until)
        throw BusFault(
            fmt::format("FRF{}: not referenced after {} s", unreferenced, params_.reference_timeout_s));
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  const auto pos = read_axes(bus, "POS?");
  for (std::size_t i = 0; i < n; ++i) publish_position(static_cast<int>(i), pos[i] * si_per_wire(i));
  publish_stamp();
  sent_ = {};
}

void Gcs2Controller::cycle(LineClient& bus) {
  const Targets t = targets();
  std::string mov;
  const auto n = static_cast<std::size_t>(axis_count());
  for (std::size_t i = 0; i < n; ++i) {
    if (!t.wanted[i]) {
      sent_[i] = false;  // once armed again, the first target is sent whatever it is
      continue;
    }
    const double target = std::clamp(t.m[i], min_m_[i], max_m_[i]);
    // The wire's resolution: 1 nm; theta: 1 udeg, 87 pm of arc at 5 mm.
    if (sent_[i] && std::abs(target - sent_m_[i]) < 0.5e-6 * si_per_wire(i)) continue;
    mov += fmt::format(" {} {:.6f}", axis_id(i), target / si_per_wire(i));
    sent_m_[i] = target;
    sent_[i] = true;
  }
  if (!mov.empty()) {
    command(bus, "MOV" + mov);
    moves_.fetch_add(1, std::memory_order_relaxed);
  }
  const auto pos = read_axes(bus, "POS?");
  for (std::size_t i = 0; i < n; ++i) publish_position(static_cast<int>(i), pos[i] * si_per_wire(i));
  publish_stamp();
}

void Gcs2Controller::safe_state(LineClient& bus) {
  sent_ = {};
  command(bus, "HLT " + axis_list(), gcs2::kStopped);  // error 10 is what a halt leaves
}

devices::DeviceSet make_gcs2_devices(const platform::PlatformConfig& config) {
  const Connection c = parse_connection(config.devices.connection, "pi-gcs2", kGcs2DefaultBaud);
  Gcs2DriverParams params = gcs2_driver_params(c);
  params.operator_speed_mm_s = config.teleop.max_jog_m_s * gcs2::kMmPerM;
  params.radius_m = config.stage.rotary.radius_m;
  if (!params.theta.empty() && !config.stage.rotary.enabled)
    throw InvalidParams("devices.connection option theta",
                        "needs the rotary axis (stage.rotary.enabled: true)");
  auto controller = std::make_shared<Gcs2Controller>(c, params);
  devices::DeviceSet d = make_sim_companions(config);
  const char* names[3] = {"gcs2_axis_x", "gcs2_axis_y", "gcs2_axis_z"};
  const stickslip::StickSlipParams axis = platform::axis_params(config);
  for (std::size_t i = 0; i < 3; ++i)
    d.axes[i] = std::make_unique<BusAxis>(names[i], controller, static_cast<int>(i), axis.integrator.dt_s,
                                          axis.drive.max_V);
  if (!params.theta.empty())
    d.rotary =
        std::make_unique<BusAxis>("gcs2_axis_theta", controller, 3, axis.integrator.dt_s, axis.drive.max_V);
  return d;
}

}  // namespace mc::drivers
