#include "microcobot/devices/parallel_positioner_controller.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <pthread.h>

#include "microcobot/core/error.h"

namespace mc::devices {
namespace {

const ParallelPositionerControllerParams& validated(const ParallelPositionerControllerParams& p) {
  p.validate();
  return p;
}

}  // namespace

void ParallelPositionerControllerParams::validate() const {
  require(std::isfinite(wake_period_s) && wake_period_s >= 1e-4 && wake_period_s <= 0.02, "wake_period_s",
          "must be within [1e-4, 0.02] s", wake_period_s);
  require(std::isfinite(host_timeout_s) && host_timeout_s >= 5.0 * wake_period_s && host_timeout_s <= 10.0,
          "host_timeout_s", "must be within [5 wake periods, 10 s]", host_timeout_s);
  require(max_periods_per_wake >= 1 && max_periods_per_wake <= 100000, "max_periods_per_wake",
          "must be within [1, 100000]", max_periods_per_wake);
  require(command_capacity >= 16 && command_capacity <= 65536, "command_capacity",
          "must be within [16, 65536]", command_capacity);
}

ParallelPositionerController::ParallelPositionerController(motion::ParallelStage& stage,
                                                           const ParallelPositionerControllerParams& params)
    : stage_(stage), p_(validated(params)), commands_(static_cast<std::size_t>(params.command_capacity)) {
  // The first status, so that the host reads the stage as it is before the first wake.
  Status s;
  publish(s);
  view_ = status_.read();
  thread_ = std::thread([this] { run(); });
  pthread_setname_np(thread_.native_handle(), "mc-positioner");
}

ParallelPositionerController::~ParallelPositionerController() {
  quit_.store(true, std::memory_order_release);
  thread_.join();
}

bool ParallelPositionerController::push(Command& c) noexcept {
  c.seq = sent_ + 1;
  if (!commands_.push(c)) return false;
  sent_ = c.seq;
  if (c.kind == Kind::kStartMove || c.kind == Kind::kFollow) motion_sent_ = c.seq;
  if (c.kind == Kind::kFollow) follow_sent_ = c.seq;
  // A stop ends what was sent before it: nothing of it is in flight any more once it is applied.
  if (c.kind == Kind::kStop || c.kind == Kind::kEmergencyStop) follow_sent_ = 0;
  return true;
}

bool ParallelPositionerController::start_move(const motion::PoseTrajectory& checked) noexcept {
  scratch_.kind = Kind::kStartMove;
  scratch_.trajectory = checked;  // in place: the optional's storage is the command's own
  return push(scratch_);
}

bool ParallelPositionerController::follow(const motion::PlatformTransform& target,
                                          const motion::PoseMoveLimits& limits) noexcept {
  scratch_.kind = Kind::kFollow;
  scratch_.target = target;
  scratch_.limits = limits;
  return push(scratch_);
}

void ParallelPositionerController::stop() noexcept {
  scratch_.kind = Kind::kStop;
  if (push(scratch_)) return;
  pending_stop_.store(true, std::memory_order_release);
  motion_sent_ = follow_sent_ = 0;
}

void ParallelPositionerController::emergency_stop() noexcept {
  scratch_.kind = Kind::kEmergencyStop;
  if (push(scratch_)) return;
  pending_emergency_stop_.store(true, std::memory_order_release);
  motion_sent_ = follow_sent_ = 0;
}

bool ParallelPositionerController::rearm() noexcept {
  scratch_.kind = Kind::kRearm;
  return push(scratch_);
}

bool ParallelPositionerController::step_leg(int leg, motion::LegPositioner positioner, int steps,
                                            double frequency_Hz) noexcept {
  scratch_.kind = Kind::kStepLeg;
  scratch_.leg = leg;
  scratch_.positioner = positioner;
  scratch_.steps = steps;
  scratch_.frequency_Hz = frequency_Hz;
  return push(scratch_);
}

void ParallelPositionerController::exchange() noexcept {
  view_ = status_.read();
  beats_.fetch_add(1, std::memory_order_relaxed);
}

void ParallelPositionerController::apply(const Command& c, Status& s) noexcept {
  s.applied = c.seq;
  switch (c.kind) {
    case Kind::kStartMove:
      s.host_lost = false;
      if (!c.trajectory || !stage_.start_move(*c.trajectory)) ++s.refused;
      break;
    case Kind::kFollow:
      s.host_lost = false;
      if (!stage_.follow(c.target, c.limits)) ++s.refused;
      break;
    case Kind::kStop:
      stage_.stop();
      break;
    case Kind::kEmergencyStop:
      stage_.emergency_stop();
      break;
    case Kind::kRearm:
      // Refused after a latched fault, or where the legs close on no pose: the stage then stays
      // halted (0 V) and the host sees the fault.
      try {
        stage_.rearm();
        s.host_lost = false;
        rearm_refused_ = false;
      } catch (...) {
        stage_.emergency_stop();
        rearm_refused_ = true;
      }
      break;
    case Kind::kStepLeg:
      try {
        stage_.step_leg(c.leg, c.positioner, c.steps, c.frequency_Hz);
      } catch (...) {
        ++s.refused;
      }
      break;
  }
}

void ParallelPositionerController::publish(Status& s) noexcept {
  s.measured = stage_.measured_pose();
  s.reference = stage_.reference_pose();
  s.truth = stage_.true_pose();
  double u = 0.0;
  for (int i = 0; i < motion::kParallelAxes; ++i) u = std::max(u, std::abs(stage_.status(i).voltage_V));
  s.max_leg_voltage_V = u;
  s.moving = stage_.moving();
  s.following = stage_.following();
  s.follow_blocked = stage_.follow_blocked();
  s.at_rest = stage_.at_rest();
  s.halted = stage_.halted();
  s.fault = stage_.fault() || rearm_refused_;
  status_.publish(s);
}

void ParallelPositionerController::run() noexcept {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const auto wake =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(p_.wake_period_s));
  const auto host_timeout =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(p_.host_timeout_s));
  const double period_s = stage_.tick_s();
  const auto max_periods = static_cast<std::uint64_t>(p_.max_periods_per_wake);
  Status s = status_.read();  // the thread is the status' only writer from here on
  std::uint64_t dropped = 0;  // periods the clock counted that a starved thread did not run
  std::uint64_t beats = beats_.load(std::memory_order_relaxed);
  auto last_beat = start;
  auto next_wake = start;
  Command c;
  while (!quit_.load(std::memory_order_acquire)) {
    while (commands_.pop(c)) apply(c, s);
    if (pending_emergency_stop_.exchange(false, std::memory_order_acq_rel)) stage_.emergency_stop();
    if (pending_stop_.exchange(false, std::memory_order_acq_rel)) stage_.stop();
    const auto now = Clock::now();
    const std::uint64_t b = beats_.load(std::memory_order_relaxed);
    if (b != beats) {
      beats = b;
      last_beat = now;
    } else if (now - last_beat > host_timeout && (stage_.moving() || stage_.following())) {
      stage_.stop();
      s.host_lost = true;
    }
    // The periods due by the wall clock since the start, less those dropped.
    const auto due =
        static_cast<std::uint64_t>(std::chrono::duration<double>(now - start).count() / period_s) - dropped;
    std::uint64_t n = due > s.periods ? due - s.periods : 0;
    if (n > max_periods) {
      dropped += n - max_periods;
      n = max_periods;
      ++s.late_wakes;
    }
    for (std::uint64_t k = 0; k < n; ++k) stage_.tick();
    s.periods += n;
    publish(s);
    next_wake += wake;
    if (next_wake < now) next_wake = now + wake;  // late: no burst of wakes to catch up
    std::this_thread::sleep_until(next_wake);
  }
}

}  // namespace mc::devices
