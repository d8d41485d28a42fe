#include "microcobot/drivers/pi_hexapod_controller.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <numbers>
#include <thread>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "microcobot/drivers/gcs2_codec.h"
#include "microcobot/drivers/gcs2_exchange.h"
#include "microcobot/drivers/gcs2_hexapod.h"

namespace mc::drivers {
namespace {

bool names_c887(const std::string& idn) {
  std::string upper;
  for (char c : idn) upper += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return upper.find("C-887") != std::string::npos;
}

// PI's pose (mm, deg) of a transform, about the pivot, and back (motion/pose.h).
std::array<double, 6> wire_pose(const motion::PlatformTransform& T, const Eigen::Vector3d& pivot_m) {
  const motion::PiPose p = motion::to_pi(T, pivot_m);
  return {p.X * gcs2::kMmPerM,    p.Y * gcs2::kMmPerM,    p.Z * gcs2::kMmPerM,
          p.U * gcs2::kDegPerRad, p.V * gcs2::kDegPerRad, p.W * gcs2::kDegPerRad};
}

motion::PlatformTransform transform_of(const std::array<double, 6>& w, const Eigen::Vector3d& pivot_m) {
  const motion::PiPose p{w[0] / gcs2::kMmPerM,    w[1] / gcs2::kMmPerM,    w[2] / gcs2::kMmPerM,
                         w[3] / gcs2::kDegPerRad, w[4] / gcs2::kDegPerRad, w[5] / gcs2::kDegPerRad};
  return motion::to_transform(p, pivot_m);
}

}  // namespace

void PiHexapodParams::validate() const {
  timing.validate();
  require(std::isfinite(reference_timeout_s) && reference_timeout_s > 0 && reference_timeout_s <= 600,
          "parallel_positioner.connection option reference_timeout_s", "must be within (0, 600] s",
          reference_timeout_s);
}

PiHexapodParams pi_hexapod_params(const Connection& c) {
  if (c.is_serial())
    throw InvalidParams("parallel_positioner.connection",
                        "'" + excerpt(c.where()) + "': the pi-hexapod driver connects over TCP (HOST:PORT)");
  check_connection_options(c, std::string(kBusTimingOptions) + ", reference, reference_timeout_s");
  PiHexapodParams p;
  p.timing = bus_timing(c, p.timing);
  p.reference = connection_number(c, "reference", 1.0, 0.0, 1.0) != 0.0;
  p.reference_timeout_s = connection_number(c, "reference_timeout_s", p.reference_timeout_s, 0.01, 600.0);
  p.validate();
  return p;
}

PiHexapodController::PiHexapodController(Connection connection, PiHexapodParams params)
    : BusController("pi-hexapod", std::move(connection), params.timing), params_(std::move(params)) {
  params_.validate();
}

std::string PiHexapodController::query(LineClient& bus, const std::string& line, double timeout_s) {
  return gcs2::query(bus, line, timeout_s > 0.0 ? deadline_in(timeout_s) : reply_deadline());
}

void PiHexapodController::command(LineClient& bus, const std::string& line, int also_ok) {
  gcs2::command(bus, line, reply_timeout(), gcs2::hexapod_error_text, also_ok);
}

std::array<double, 6> PiHexapodController::read_six(LineClient& bus, const std::string& mnemonic) {
  const std::string line = mnemonic + " X Y Z U V W";
  const std::string reply = query(bus, line);
  std::vector<std::pair<std::string, double>> values;
  try {
    values = gcs2::parse_axis_values(reply);
  } catch (const Error& e) {
    throw BusFault("'" + line + "': " + e.what());
  }
  std::array<double, 6> out{};
  bool ok = values.size() == 6;
  for (std::size_t i = 0; ok && i < 6; ++i) {
    ok = values[i].first == gcs2::kHexapodAxes[i];
    out[i] = values[i].second;
  }
  if (!ok) throw BusFault("'" + line + "': the reply '" + excerpt(reply, 80) + "' does not give X Y Z U V W");
  return out;
}

motion::PlatformTransform PiHexapodController::read_pose(LineClient& bus) {
  return transform_of(read_six(bus, "POS?"), pivot_m_);
}

void PiHexapodController::handshake(LineClient& bus) {
  const auto idn = gcs2::reply_lines(query(bus, "*IDN?", timing().connect_timeout_s));
  if (idn.size() != 1 || idn[0].empty())
    throw BusFault("*IDN? reads '" + excerpt(idn.empty() ? "" : idn[0], 80) + "': not an identification");
  if (!names_c887(idn[0]))
    throw BusFault("*IDN? reads '" + excerpt(idn[0], 80) + "': not a PI C-887 hexapod controller");
  set_identity(idn[0]);
  gcs2::clear_errors(bus, reply_timeout());
  const auto found = gcs2::reply_lines(query(bus, "SAI? ALL"));
  std::string found_list;
  for (const auto& a : found) found_list += (found_list.empty() ? "" : ", ") + a;
  for (const char* axis : gcs2::kHexapodAxes)
    if (std::find(found.begin(), found.end(), axis) == found.end())
      throw BusFault("SAI? ALL lists axes [" + excerpt(found_list) + "]: no axis '" + axis +
                     "' (a hexapod has X Y Z U V W)");
  // Poses read and move in the enabled coordinate system: the driver's are the root one's.
  const auto ken = gcs2::reply_lines(query(bus, "KEN?"));
  if (ken.size() != 1 || ken[0] != "ZERO=ZERO")
    throw BusFault(
        "KEN? reads '" + excerpt(ken.empty() ? "" : ken[0]) +
        "': a user coordinate system is enabled (KEN ZERO gives the root one the driver works in)");
  // The pivot: PI's poses turn about it (motion/pose.h), so the conversions need it.
  std::vector<std::pair<std::string, double>> spi;
  try {
    spi = gcs2::parse_axis_values(query(bus, "SPI? R S T"));
  } catch (const Error& e) {
    throw BusFault(std::string("'SPI? R S T': ") + e.what());
  }
  if (spi.size() != 3 || spi[0].first != "R" || spi[1].first != "S" || spi[2].first != "T")
    throw BusFault("'SPI? R S T': the reply does not give R S T");
  pivot_m_ = Eigen::Vector3d(spi[0].second, spi[1].second, spi[2].second) / gcs2::kMmPerM;
  auto referenced = [&] {
    const auto r = read_six(bus, "FRF?");
    return std::all_of(r.begin(), r.end(), [](double v) { return v == 1.0; });
  };
  if (!referenced()) {
    if (!params_.reference)
      throw BusFault("the hexapod is not referenced (FRF? 0) and the option reference=0 forbids FRF");
    command(bus, "FRF X Y Z U V W");
    const auto until = deadline_in(params_.reference_timeout_s);
    while (!referenced()) {
      if (Clock::now() > until)
        throw BusFault(
            fmt::format("FRF X Y Z U V W: not referenced after {} s", params_.reference_timeout_s));
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  const auto vls = gcs2::reply_lines(query(bus, "VLS?"));
  const auto v = vls.size() == 1 ? gcs2::parse_number(vls[0]) : std::nullopt;
  if (!v) throw BusFault("VLS? reads '" + excerpt(vls.empty() ? "" : vls[0]) + "': not a velocity");
  vls_mm_s_ = *v;
  // Again at the end: the controller may have raised one of an earlier session's meanwhile (a move
  // of a client gone, stopped as the connection closed), which the first MOV must not read as its own.
  gcs2::clear_errors(bus, reply_timeout());
  // A move left in the ring by a bus that faulted is not sent after the reconnect.
  HexapodMove stale;
  while (moves_.pop(stale)) bus_.move_done = std::max(bus_.move_done, stale.seq);
  stop_sent_ = stop_seq_.load(std::memory_order_acquire);
  bus_.stop_done = stop_sent_;
  bus_.measured = read_pose(bus);
  bus_.held = bus_.measured;  // the controller holds where it stands
  bus_.moving = false;
  bus_.on_target = false;
  status_.publish(bus_);
  publish_stamp();
}

void PiHexapodController::send_move(LineClient& bus, const HexapodMove& m) {
  if (m.speed_mm_s > 0.0 && std::abs(m.speed_mm_s - vls_mm_s_) > 0.5e-6) {
    command(bus, fmt::format("VLS {:.6f}", m.speed_mm_s));
    vls_mm_s_ = m.speed_mm_s;
  }
  const auto w = wire_pose(m.goal, pivot_m_);
  command(bus, fmt::format("MOV X {:.6f} Y {:.6f} Z {:.6f} U {:.6f} V {:.6f} W {:.6f}", w[0], w[1], w[2],
                           w[3], w[4], w[5]));
  moves_sent_.fetch_add(1, std::memory_order_relaxed);
  bus_.held = m.goal;
}

void PiHexapodController::cycle(LineClient& bus) {
  const std::uint64_t stop = stop_seq_.load(std::memory_order_acquire);
  HexapodMove m;
  while (moves_.pop(m)) {
    // Done once taken, sent or not: a MOV that faults the bus is not waited for after a reconnect.
    bus_.move_done = std::max(bus_.move_done, m.seq);
    if (m.seq > stop) send_move(bus, m);  // a move numbered before the last stop is dropped
  }
  bus_.measured = read_pose(bus);
  const std::string mask = gcs2::reply_lines(query(bus, std::string(1, gcs2::kMotionStatus))).at(0);
  unsigned bits = 0;
  const auto [end, ec] = std::from_chars(mask.data(), mask.data() + mask.size(), bits, 16);
  if (mask.empty() || ec != std::errc() || end != mask.data() + mask.size())
    throw BusFault("#5: the reply '" + excerpt(mask, 40) + "' is not a hexadecimal motion mask");
  bus_.moving = (bits & 0x3Fu) != 0;
  const auto ont = read_six(bus, "ONT?");
  bus_.on_target = std::all_of(ont.begin(), ont.end(), [](double v) { return v == 1.0; });
  // A stop is over once nothing moves: the controller holds where it stopped.
  if (stop_sent_ > bus_.stop_done && !bus_.moving) {
    bus_.held = bus_.measured;
    bus_.stop_done = stop_sent_;
  }
  status_.publish(bus_);
  publish_stamp();
}

void PiHexapodController::safe_state(LineClient& bus) {
  // Every move asked before the stop is dropped (cycle()), and the stop is done once #5 reads 0.
  stop_sent_ = std::max(stop_sent_, stop_seq_.load(std::memory_order_acquire));
  command(bus, std::string(1, gcs2::kStopAll), gcs2::kStopped);  // error 10 is what #24 leaves
}

}  // namespace mc::drivers
