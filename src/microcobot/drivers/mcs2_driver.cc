#include "microcobot/drivers/mcs2_driver.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <numbers>
#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "microcobot/drivers/mcs2_codec.h"
#include "microcobot/drivers/sim_companions.h"

namespace mc::drivers {
namespace {

constexpr double kPmPerM = 1e12;
constexpr double kNdegPerDeg = 1e9;
constexpr double kMmPerM = 1e3;
/// The longest a step run may take to show as moving in :CHAN<n>:STAT? after its :MOVE.
constexpr double kRunStartWithin_s = 0.02;

std::string trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\r' || s.back() == '\n' || s.back() == ' ')) s.pop_back();
  std::size_t k = 0;
  while (k < s.size() && s[k] == ' ') ++k;
  return s.substr(k);
}

bool names_mcs2(const std::string& idn) {
  std::string upper;
  for (char c : idn) upper += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return upper.find("MCS2") != std::string::npos;
}

}  // namespace

void Mcs2DriverParams::validate() const {
  timing.validate();
  for (int c : channels)
    require(c >= 0 && c <= kMcs2MaxChannel, "devices.connection option channels",
            "each channel must be within 0..23", static_cast<double>(c));
  require(channels[0] != channels[1] && channels[1] != channels[2] && channels[0] != channels[2],
          "devices.connection option channels", "must name three different channels");
  require(theta == -1 || (theta >= 0 && theta <= kMcs2MaxChannel && theta != channels[0] &&
                          theta != channels[1] && theta != channels[2]),
          "devices.connection option theta", "must be a channel within 0..23 other than X's, Y's and Z's",
          theta);
  require(std::isfinite(radius_m) && radius_m > 0, "stage.rotary.radius_m", "must be > 0", radius_m);
  require(std::isfinite(reference_timeout_s) && reference_timeout_s > 0 && reference_timeout_s <= 600,
          "devices.connection option reference_timeout_s", "must be within (0, 600] s", reference_timeout_s);
  require(std::isfinite(velocity_mm_s) && velocity_mm_s >= 0 && velocity_mm_s <= 1e3,
          "devices.connection option velocity_mm_s", "must be within [0, 1000] mm/s (0: the controller's)",
          velocity_mm_s);
  if (sensorless_step) step.validate("MCS2", mcs2::kFullAmplitude_V, mcs2::kMaxStepFrequency_Hz);
}

Mcs2DriverParams mcs2_driver_params(const Connection& c) {
  check_connection_options(c, std::string(kBusTimingOptions) +
                                  ", channels, theta, reference, "
                                  "reference_timeout_s, velocity_mm_s, sensorless, " +
                                  std::string(kStepDriveOptions));
  Mcs2DriverParams p;
  p.timing = bus_timing(c, p.timing);
  p.reference_timeout_s = connection_number(c, "reference_timeout_s", p.reference_timeout_s, 0.01, 600.0);
  p.velocity_mm_s = connection_number(c, "velocity_mm_s", p.velocity_mm_s, 0.0, 1e3);
  if (const auto it = c.options.find("reference"); it != c.options.end()) {
    if (it->second != "auto" && it->second != "require")
      throw InvalidParams(
          "devices.connection option reference",
          "'" + excerpt(it->second) + "' must be auto (:REF what is unreferenced) or require");
    p.reference = it->second == "auto";
  }
  auto channel_number = [](const std::string& option, const std::string& v) {
    const auto n = mcs2::parse_integer(v);
    if (!n || v.empty() || v[0] == '+' || v[0] == '-' || *n > kMcs2MaxChannel)
      throw InvalidParams("devices.connection option " + option,
                          "'" + excerpt(v) + "' must be a channel index within 0..23");
    return static_cast<int>(*n);
  };
  if (const auto it = c.options.find("channels"); it != c.options.end()) {
    const std::string& v = it->second;
    const auto a = v.find('+'), b = v.find('+', a == std::string::npos ? a : a + 1);
    if (a == std::string::npos || b == std::string::npos || v.find('+', b + 1) != std::string::npos)
      throw InvalidParams("devices.connection option channels",
                          "'" + excerpt(v) + "' must be three channel indices joined by '+' (e.g. 0+1+2)");
    p.channels = {channel_number("channels", v.substr(0, a)),
                  channel_number("channels", v.substr(a + 1, b - a - 1)),
                  channel_number("channels", v.substr(b + 1))};
  }
  if (const auto it = c.options.find("theta"); it != c.options.end())
    p.theta = channel_number("theta", it->second);
  if (const auto it = c.options.find("sensorless"); it != c.options.end()) {
    if (it->second != "refuse" && it->second != "step")
      throw InvalidParams("devices.connection option sensorless",
                          "'" + excerpt(it->second) +
                              "' must be refuse (a channel without sensor fails the configuration) or step "
                              "(stepped open loop, its position counted)");
    p.sensorless_step = it->second == "step";
  }
  for (const char* o :
       {"voltage_V", "frequency_Hz", "max_run_s", "step_up_nm", "step_down_nm", "deadband_nm"})
    if (c.options.count(o) && !p.sensorless_step)
      throw InvalidParams(std::string("devices.connection option ") + o,
                          "sets how a channel without sensor steps: it needs sensorless=step");
  p.step = step_drive_options(c, p.step, mcs2::kFullAmplitude_V, mcs2::kMaxStepFrequency_Hz);
  // The steps left to the model are known once the platform's is (make_mcs2_devices): the rest is
  // checked here with a stand-in step.
  Mcs2DriverParams checked = p;
  if (checked.step.step_up_m == 0.0) checked.step.step_up_m = 1e-9;
  if (checked.step.step_down_m == 0.0) checked.step.step_down_m = 1e-9;
  checked.validate();
  return p;
}

Mcs2Controller::Mcs2Controller(Connection connection, Mcs2DriverParams params)
    : BusController("smaract-mcs2", std::move(connection), params.timing), params_(std::move(params)) {
  params_.validate();
}

std::string Mcs2Controller::channel_list() const {
  std::string list = fmt::format("{} {} {}", params_.channels[0], params_.channels[1], params_.channels[2]);
  return params_.theta < 0 ? list : fmt::format("{} {}", list, params_.theta);
}

double Mcs2Controller::si_per_wire(std::size_t i) const {
  return i < 3 ? 1.0 / kPmPerM : params_.radius_m * std::numbers::pi / 180.0 / kNdegPerDeg;
}

std::vector<std::string> Mcs2Controller::exchange(LineClient& bus, const std::vector<std::string>& lines,
                                                  double timeout_s) {
  const auto deadline = timeout_s > 0.0 ? deadline_in(timeout_s) : reply_deadline();
  std::vector<std::string> replies;
  std::string out;
  for (const auto& l : lines) {
    out += l;
    out += mcs2::kEol;
    const bool is_query = !l.empty() && l.back() == '?';
    if (!is_query && &l != &lines.back()) continue;
    if (!bus.send(out, deadline)) throw BusFault("'" + excerpt(l, 60) + "': " + bus.error());
    out.clear();
    if (!is_query) break;
    std::string reply;
    if (!bus.read_until(
            reply, [](const std::string& t) { return mcs2::reply_end(t); }, deadline)) {
      const std::string got = reply.empty() ? std::string() : " (got '" + excerpt(reply, 60) + "')";
      throw BusFault("'" + l + "': " + bus.error() + got);
    }
    replies.push_back(trimmed(std::move(reply)));
  }
  return replies;
}

std::string Mcs2Controller::query(LineClient& bus, const std::string& line, double timeout_s) {
  return exchange(bus, {line}, timeout_s).front();
}

std::int64_t Mcs2Controller::query_integer(LineClient& bus, const std::string& line) {
  const std::string reply = query(bus, line);
  const auto v = mcs2::parse_integer(reply);
  if (!v) throw BusFault("'" + line + "': a reply that is not an integer: '" + excerpt(reply, 60) + "'");
  return *v;
}

void Mcs2Controller::check_errors(LineClient& bus, std::int64_t count, const std::string& after) {
  if (count == 0) return;
  const std::string reply = query(bus, ":SYST:ERR:NEXT?");
  const auto e = mcs2::parse_error_reply(reply);
  if (!e)
    throw BusFault("':SYST:ERR:NEXT?' after '" + excerpt(after, 60) + "': not an error reply: '" +
                   excerpt(reply, 60) + "'");
  throw BusFault(fmt::format("'{}': controller error {} ({})", excerpt(after, 60), e->first, e->second));
}

void Mcs2Controller::command(LineClient& bus, const std::vector<std::string>& lines,
                             const std::string& after) {
  std::vector<std::string> all = lines;
  all.push_back(":SYST:ERR:COUN?");
  const auto replies = exchange(bus, all);
  const auto count = mcs2::parse_integer(replies.back());
  if (!count)
    throw BusFault("':SYST:ERR:COUN?': a reply that is not an integer: '" + excerpt(replies.back(), 60) +
                   "'");
  check_errors(bus, *count, lines.empty() ? after : lines.front());
}

void Mcs2Controller::handshake(LineClient& bus) {
  const std::string idn = query(bus, "*IDN?", timing().connect_timeout_s);
  if (!names_mcs2(idn))
    throw BusFault("*IDN? reads '" + excerpt(idn, 80) +
                   "': not a SmarAct MCS2 (the driver speaks its ASCII interface)");
  set_identity(idn);
  // A stale error of an earlier session is not this one's: the queue is drained (20 at most).
  const auto stale = std::min<std::int64_t>(query_integer(bus, ":SYST:ERR:COUN?"), 32);
  for (std::int64_t k = 0; k < stale; ++k) query(bus, ":SYST:ERR:NEXT?");
  const auto count = query_integer(bus, ":DEV:NOCH?");
  const auto n = static_cast<std::size_t>(axis_count());
  for (std::size_t i = 0; i < n; ++i)
    if (channel(i) >= count)
      throw BusFault(
          fmt::format(":DEV:NOCH? reads {}: no channel {} (the configuration wants channels {}; "
                      "options channels=A+B+C, theta=D)",
                      count, channel(i), channel_list()));
  std::vector<int> unreferenced;
  for (std::size_t i = 0; i < n; ++i) {
    const int c = channel(i);
    const auto state = static_cast<std::uint32_t>(query_integer(bus, fmt::format(":CHAN{}:STAT?", c)));
    stepped_[i] = !(state & mcs2::channel_state::kSensorPresent);
    if (stepped_[i] && !params_.sensorless_step)
      throw BusFault(fmt::format(
          "channel {}: no sensor present (:CHAN{}:STAT? {:#x}): the driver moves it open-loop only with the "
          "option sensorless=step (its position then counted)",
          c, c, state));
    if (!stepped_[i] && !(state & mcs2::channel_state::kIsReferenced)) unreferenced.push_back(c);
    const auto unit = query_integer(bus, fmt::format(":CHAN{}:TUN:BASE:UNIT?", c));
    const auto wanted = i < 3 ? mcs2::kUnitMeter : mcs2::kUnitDegree;
    if (unit != wanted)
      throw BusFault(fmt::format(
          "channel {}: base unit {} (:CHAN{}:TUN:BASE:UNIT?), not {} ({})", c, unit, c, wanted,
          i < 3 ? "metre: a linear positioner for X, Y, Z" : "degree: a rotary positioner for theta"));
    constexpr double kInf = std::numeric_limits<double>::infinity();
    if (stepped_[i]) {
      // The range limit is on the sensor's scale; the count starts where the slider was.
      min_m_[i] = -kInf;
      max_m_[i] = kInf;
      count_run(i, true);  // a run the lost connection cut: counted as far as its time tells
      continue;
    }
    const auto lo = query_integer(bus, fmt::format(":CHAN{}:RLIM:MIN?", c));
    const auto hi = query_integer(bus, fmt::format(":CHAN{}:RLIM:MAX?", c));
    const bool limited = lo != 0 || hi != 0;  // both 0: the controller has no range limit
    min_m_[i] = limited ? static_cast<double>(lo) * si_per_wire(i) : -kInf;
    max_m_[i] = limited ? static_cast<double>(hi) * si_per_wire(i) : kInf;
    if (limited && !(lo <= 0 && hi >= 0))
      throw BusFault(fmt::format("channel {}: RLIM:MIN?..MAX? = {}..{} {} does not hold the stage's home (0)",
                                 c, lo, hi, i < 3 ? "pm" : "ndeg"));
  }
  std::vector<std::string> setup;
  for (std::size_t i = 0; i < n; ++i) {
    if (stepped_[i]) {
      setup.push_back(fmt::format(":CHAN{}:MMOD {}", channel(i), static_cast<int>(mcs2::kStep)));
      setup.push_back(
          fmt::format(":CHAN{}:STEP:FREQ {}", channel(i), std::llround(params_.step.frequency_Hz)));
      setup.push_back(fmt::format(":CHAN{}:STEP:AMPL {}", channel(i),
                                  std::llround(params_.step.voltage_V / mcs2::kFullAmplitude_V *
                                               static_cast<double>(mcs2::kFullAmplitude))));
      continue;
    }
    setup.push_back(fmt::format(":CHAN{}:MMOD {}", channel(i), static_cast<int>(mcs2::kAbsolute)));
    setup.push_back(fmt::format(":CHAN{}:HOLD -1", channel(i)));  // hold the target for ever
    if (i < 3 && params_.velocity_mm_s > 0.0)
      setup.push_back(
          fmt::format(":CHAN{}:VEL {}", channel(i), std::llround(params_.velocity_mm_s / kMmPerM * kPmPerM)));
  }
  command(bus, setup);
  for (std::size_t i = 0; i < 3; ++i) {
    if (stepped_[i]) continue;
    const double vel_mm_s =
        static_cast<double>(query_integer(bus, fmt::format(":CHAN{}:VEL?", channel(i)))) * kMmPerM / kPmPerM;
    if (vel_mm_s > 0.0 && vel_mm_s < params_.operator_speed_mm_s)
      spdlog::warn(
          "smaract-mcs2: channel {} moves at VEL {:g} mm/s, slower than the operator's {:g} mm/s: "
          "the stage will lag the coupling's target (option velocity_mm_s=1 sets VEL at configure)",
          channel(i), vel_mm_s, params_.operator_speed_mm_s);
  }
  if (!unreferenced.empty()) {
    std::string names;
    for (int c : unreferenced) names += fmt::format(" {}", c);
    if (!params_.reference)
      throw BusFault("channels" + names +
                     " are not referenced (:CHAN<n>:STAT? without 0x80) and the option reference=require "
                     "forbids :REF");
    std::vector<std::string> refs;
    for (int c : unreferenced) refs.push_back(fmt::format(":REF{}", c));
    command(bus, refs);
    const auto until = deadline_in(params_.reference_timeout_s);
    for (bool done = false; !done;) {
      done = true;
      for (int c : unreferenced) {
        const auto s = static_cast<std::uint32_t>(query_integer(bus, fmt::format(":CHAN{}:STAT?", c)));
        if ((s & mcs2::channel_state::kMovementFailed) && !(s & mcs2::channel_state::kReferencing) &&
            !(s & mcs2::channel_state::kIsReferenced))
          throw BusFault(fmt::format(":REF{}: the reference failed (:CHAN{}:STAT? {:#x})", c, c, s));
        done = done && (s & mcs2::channel_state::kIsReferenced) && !(s & mcs2::channel_state::kReferencing);
      }
      if (done) break;
      if (Clock::now() > until)
        throw BusFault(fmt::format(":REF{}: not referenced after {} s", names, params_.reference_timeout_s));
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    command(bus, {}, ":REF" + names);  // an error the reference left (the queue read once more)
  }
  poll_lines_.clear();
  poll_lines_.push_back(":SYST:ERR:COUN?");
  for (std::size_t i = 0; i < n; ++i)
    poll_lines_.push_back(fmt::format(":CHAN{}:{}?", channel(i), stepped_[i] ? "STAT" : "POS"));
  sent_ = {};
  poll(bus, {});  // the first positions; no target is sent before the axes are armed
}

void Mcs2Controller::cycle(LineClient& bus) {
  const Targets t = targets();
  const auto n = static_cast<std::size_t>(axis_count());
  std::vector<std::string> moves;
  for (std::size_t i = 0; i < n; ++i) {
    if (stepped_[i]) {
      if (t.wanted[i]) step_toward(i, t.m[i], moves);
      continue;
    }
    if (!t.wanted[i]) {
      sent_[i] = false;  // once armed again, the first target is sent whatever it is
      continue;
    }
    const double target = std::clamp(t.m[i], min_m_[i], max_m_[i]);
    // Sent again once it moved by half a nm (theta: half a nm of arc): the coupling's target
    // at rest does not flood the controller with the same move.
    if (sent_[i] && std::abs(target - sent_m_[i]) < 0.5e-9) continue;
    moves.push_back(fmt::format(":MOVE{} {}", channel(i), std::llround(target / si_per_wire(i))));
    sent_m_[i] = target;
    sent_[i] = true;
  }
  poll(bus, moves);
  if (!moves.empty()) moves_.fetch_add(1, std::memory_order_relaxed);
}

void Mcs2Controller::step_toward(std::size_t i, double target_m, std::vector<std::string>& moves) {
  if (run_[i] != 0) return;  // a new :MOVE would replace the run under way, its periods uncounted
  const long long periods = params_.step.periods_toward(target_m - est_m_[i]);
  if (periods == 0) return;
  moves.push_back(fmt::format(":MOVE{} {}", channel(i), periods));
  run_[i] = periods;
  run_start_[i] = Clock::now();
  run_seen_moving_[i] = false;
  periods_[i].fetch_add(periods);
}

void Mcs2Controller::count_run(std::size_t i, bool stopped) {
  if (run_[i] == 0) return;
  long long played = run_[i];
  if (stopped) {
    const double elapsed_s = std::chrono::duration<double>(Clock::now() - run_start_[i]).count();
    const auto by_time = static_cast<long long>(elapsed_s * params_.step.frequency_Hz);
    played = run_[i] > 0 ? std::min(run_[i], by_time) : std::max(run_[i], -by_time);
  }
  est_m_[i] += params_.step.displacement_m(played);
  run_[i] = 0;
}

void Mcs2Controller::poll(LineClient& bus, std::vector<std::string> lines) {
  const std::string after = lines.empty() ? std::string(":CHAN<n>:POS?") : lines.front();
  const std::size_t first = lines.size();
  lines.insert(lines.end(), poll_lines_.begin(), poll_lines_.end());
  const auto replies = exchange(bus, lines);
  const auto errors = mcs2::parse_integer(replies[0]);
  if (!errors)
    throw BusFault("':SYST:ERR:COUN?': a reply that is not an integer: '" + excerpt(replies[0], 60) + "'");
  check_errors(bus, *errors, after);
  for (std::size_t i = 0; i + 1 < replies.size(); ++i) {
    if (stepped_[i]) {
      const auto state = mcs2::parse_integer(replies[i + 1]);
      if (!state)
        throw BusFault("'" + lines[first + i + 1] + "': a reply that is not a channel state: '" +
                       excerpt(replies[i + 1], 60) + "'");
      // The run is over once its periods' time is gone and the channel, seen moving, no longer
      // moves; a controller may report it late (the twin starts it at its loop's next tick), so a
      // run never seen moving is over only kRunStartWithin_s after its time.
      const bool moving = *state & mcs2::channel_state::kActivelyMoving;
      run_seen_moving_[i] = run_seen_moving_[i] || moving;
      const double run_s = static_cast<double>(std::abs(run_[i])) / params_.step.frequency_Hz;
      const double elapsed_s = std::chrono::duration<double>(Clock::now() - run_start_[i]).count();
      if (run_[i] != 0 && !moving && elapsed_s >= run_s + (run_seen_moving_[i] ? 0.0 : kRunStartWithin_s))
        count_run(i, false);
      publish_position(static_cast<int>(i), est_m_[i]);
      continue;
    }
    // pm (ndeg) as an integer; a decimal is rounded (the EPICS driver reads it as a double).
    const auto pos = mcs2::parse_rounded(replies[i + 1]);
    if (!pos)
      throw BusFault("'" + lines[first + i + 1] + "': a reply that is not a position: '" +
                     excerpt(replies[i + 1], 60) + "'");
    publish_position(static_cast<int>(i), static_cast<double>(*pos) * si_per_wire(i));
  }
  publish_stamp();
}

void Mcs2Controller::safe_state(LineClient& bus) {
  sent_ = {};
  std::vector<std::string> lines;
  for (std::size_t i = 0; i < static_cast<std::size_t>(axis_count()); ++i) {
    lines.push_back(fmt::format(":STOP{}", channel(i)));
    count_run(i, true);  // the periods played before the stop, as far as their time tells
  }
  lines.push_back(":SYST:ERR:COUN?");  // its reply: the stops were read
  exchange(bus, lines);
}

devices::DeviceSet make_mcs2_devices(const platform::PlatformConfig& config) {
  const Connection c = parse_connection(config.devices.connection, "smaract-mcs2");
  if (c.is_serial())
    throw InvalidParams("devices.connection",
                        "'" + excerpt(c.serial.path) +
                            "': the smaract-mcs2 driver speaks the MCS2's network interface, HOST:PORT "
                            "(port 55551)");
  Mcs2DriverParams params = mcs2_driver_params(c);
  params.operator_speed_mm_s = config.teleop.max_jog_m_s * kMmPerM;
  params.radius_m = config.stage.rotary.radius_m;
  if (params.theta >= 0 && !config.stage.rotary.enabled)
    throw InvalidParams("devices.connection option theta",
                        "needs the rotary axis (stage.rotary.enabled: true)");
  const stickslip::StickSlipParams axis = platform::axis_params(config);
  if (params.sensorless_step) {
    steps_from_model(params.step, axis);  // the step of one period from the model of these axes
    spdlog::info(
        "smaract-mcs2 driver: a channel without sensor steps {:.1f} nm up, {:.1f} nm down per period "
        "at {:g} V, {:g} Hz (counted)",
        1e9 * params.step.step_up_m, 1e9 * params.step.step_down_m, params.step.voltage_V,
        params.step.frequency_Hz);
  }
  auto controller = std::make_shared<Mcs2Controller>(c, params);  // validates (a model step of 0 is refused)
  devices::DeviceSet d = make_sim_companions(config);
  const char* names[3] = {"mcs2_axis_x", "mcs2_axis_y", "mcs2_axis_z"};
  for (std::size_t i = 0; i < 3; ++i)
    d.axes[i] = std::make_unique<BusAxis>(names[i], controller, static_cast<int>(i), axis.integrator.dt_s,
                                          axis.drive.max_V);
  if (params.theta >= 0)
    d.rotary =
        std::make_unique<BusAxis>("mcs2_axis_theta", controller, 3, axis.integrator.dt_s, axis.drive.max_V);
  return d;
}

}  // namespace mc::drivers
