#include "microcobot/drivers/bus_controller.h"

#include <algorithm>
#include <cmath>

#include <spdlog/spdlog.h>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"

namespace mc::drivers {
namespace {

std::int64_t now_ns() noexcept {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

void BusTiming::validate() const {
  require(std::isfinite(connect_timeout_s) && connect_timeout_s >= 0.01 && connect_timeout_s <= 60.0,
          "devices.connection option connect_timeout_s", "must be within [0.01, 60] s", connect_timeout_s);
  require(std::isfinite(reply_timeout_s) && reply_timeout_s >= 0.001 && reply_timeout_s <= 10.0,
          "devices.connection option timeout_s", "must be within [0.001, 10] s", reply_timeout_s);
  require(std::isfinite(poll_period_s) && poll_period_s >= 1e-4 && poll_period_s <= 1.0,
          "devices.connection option poll_s", "must be within [0.0001, 1] s", poll_period_s);
  require(std::isfinite(stale_timeout_s) && stale_timeout_s > poll_period_s && stale_timeout_s <= 10.0,
          "devices.connection option stale_s", "must exceed the poll period and be at most 10 s",
          stale_timeout_s);
}

BusTiming bus_timing(const Connection& c, BusTiming t) {
  t.reply_timeout_s = connection_number(c, "timeout_s", t.reply_timeout_s, 0.001, 10.0);
  t.connect_timeout_s = connection_number(c, "connect_timeout_s", t.connect_timeout_s, 0.01, 60.0);
  t.poll_period_s = connection_number(c, "poll_s", t.poll_period_s, 1e-4, 1.0);
  t.stale_timeout_s = connection_number(c, "stale_s", t.stale_timeout_s, 1e-3, 10.0);
  return t;
}

BusController::BusController(std::string driver, Connection connection, BusTiming timing)
    : driver_(std::move(driver)), connection_(std::move(connection)), timing_(timing) {
  timing_.validate();
}

BusController::~BusController() { shutdown(); }

void BusController::configure() {
  if (running_.load(std::memory_order_acquire) && !faulted()) return;  // up and healthy
  shutdown();
  const std::string where = driver_ + " controller at " + connection_.where();
  bus_.open(connection_, timing_.connect_timeout_s);
  try {
    handshake(bus_);
  } catch (const BusFault& e) {
    bus_.close();
    throw InvalidInput(where + ": " + e.what());
  } catch (const Error& e) {
    bus_.close();
    throw InvalidInput(where + ": " + e.what());
  }
  {
    std::lock_guard lock(reason_mutex_);
    reason_.clear();
  }
  for (auto& a : armed_) a.store(false);
  for (auto& g : given_) g.store(false);
  safe_seen_ = safe_requests_.load(std::memory_order_acquire);  // the ones before: nothing was moving
  stop_.store(false);
  faulted_.store(false, std::memory_order_release);
  running_.store(true, std::memory_order_release);
  thread_ = std::thread([this] { run(); });
}

void BusController::shutdown() noexcept {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
  running_.store(false, std::memory_order_release);
  bus_.close();
}

void BusController::set_target(int axis, double target_m) noexcept {
  const auto k = static_cast<std::size_t>(axis);
  if (!armed_[k].load(std::memory_order_relaxed) || !std::isfinite(target_m)) return;
  target_m_[k].store(target_m, std::memory_order_relaxed);
  given_[k].store(true, std::memory_order_release);
}

void BusController::arm(int axis, bool on) noexcept {
  const auto k = static_cast<std::size_t>(axis);
  given_[k].store(false, std::memory_order_relaxed);
  armed_[k].store(on, std::memory_order_release);
}

bool BusController::fresh() const noexcept {
  if (faulted() || !running_.load(std::memory_order_acquire)) return false;
  const double age_s = 1e-9 * static_cast<double>(now_ns() - stamp_ns_.load(std::memory_order_acquire));
  return age_s <= timing_.stale_timeout_s;
}

std::string BusController::fault_reason() const {
  std::lock_guard lock(reason_mutex_);
  return reason_;
}

BusController::Targets BusController::targets() const noexcept {
  Targets t;
  for (std::size_t i = 0; i < kMaxAxes; ++i) {
    t.wanted[i] = armed_[i].load(std::memory_order_acquire) && given_[i].load(std::memory_order_acquire);
    t.m[i] = target_m_[i].load(std::memory_order_relaxed);
  }
  return t;
}

void BusController::publish_position(int axis, double m) noexcept {
  position_m_[static_cast<std::size_t>(axis)].store(m, std::memory_order_relaxed);
}

void BusController::publish_stamp() noexcept { stamp_ns_.store(now_ns(), std::memory_order_release); }

BusController::Clock::time_point BusController::deadline_in(double s) const {
  return Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

BusController::Clock::duration BusController::reply_timeout() const {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timing_.reply_timeout_s));
}

BusController::Clock::time_point BusController::reply_deadline() const {
  return Clock::now() + reply_timeout();
}

void BusController::fail(const std::string& reason) noexcept {
  try {
    std::lock_guard lock(reason_mutex_);
    reason_ = reason;
  } catch (...) {
  }
  faulted_.store(true, std::memory_order_release);  // the loop faults the platform at its next tick
  if (bus_.is_open()) {
    try {
      bus_.discard_input();
      safe_state(bus_);  // best effort: the connection may be what failed
    } catch (...) {
    }
    safe_done_.fetch_add(1, std::memory_order_acq_rel);
  }
  bus_.close();
  running_.store(false, std::memory_order_release);
  try {
    spdlog::error("{} driver: {} (every device to its safe state)", driver_, excerpt(reason, 200));
  } catch (...) {
  }
}

void BusController::run() noexcept {
  const auto period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timing_.poll_period_s));
  while (!stop_.load(std::memory_order_relaxed)) {
    const auto start = Clock::now();
    try {
      const std::uint64_t requested = safe_requests_.load(std::memory_order_acquire);
      if (requested != safe_seen_) {
        safe_seen_ = requested;
        safe_state(bus_);
        safe_done_.fetch_add(1, std::memory_order_acq_rel);
      }
      cycle(bus_);
      cycles_.fetch_add(1, std::memory_order_relaxed);
    } catch (const std::exception& e) {
      fail(e.what());
      return;
    }
    // Until the next cycle; a safe-state request is served at once.
    while (!stop_.load(std::memory_order_relaxed) && Clock::now() - start < period &&
           safe_requests_.load(std::memory_order_acquire) == safe_seen_)
      std::this_thread::sleep_for(std::min<Clock::duration>(std::chrono::microseconds(200), period));
  }
  // Shut down (the platform is gone or reconfigures): the controller stops every axis.
  try {
    bus_.discard_input();
    safe_state(bus_);
    safe_done_.fetch_add(1, std::memory_order_acq_rel);
  } catch (...) {
  }
}

BusAxis::BusAxis(std::string name, std::shared_ptr<BusController> controller, int index,
                 double sample_period_s, double max_voltage_V)
    : SlaveAxis(std::move(name)),
      controller_(std::move(controller)),
      index_(index),
      period_s_(sample_period_s),
      max_V_(max_voltage_V) {}

void BusAxis::command_target_m(double target_m, double /*velocity_m_s*/) noexcept {
  if (active()) controller_->set_target(index_, target_m);
}

void BusAxis::update(double /*dt_s*/) noexcept {
  if (controller_->faulted() && state() != devices::Lifecycle::kFault) fault();
}

void BusAxis::enter_safe_state() noexcept {
  controller_->arm(index_, false);
  controller_->request_safe_state();
}

}  // namespace mc::drivers
