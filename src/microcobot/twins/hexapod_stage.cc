#include "microcobot/twins/hexapod_stage.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"
#include "microcobot/motion/step_map.h"
#include "microcobot/stickslip/actuator.h"

namespace mc::twins {

namespace {

/// The legs' actuator model (the project's SLC-1720 default) and its step map: immutable once
/// built, shared by every hexapod stage of the process (the step map is the expensive part).
struct LegModel {
  stickslip::ActuatorModel model{stickslip::StickSlipParams{}};
  motion::StepMap map{model};
};
const LegModel& leg_model() {
  static const LegModel m;
  return m;
}

}  // namespace

void HexapodStageParams::validate() const {
  stage.validate();
  require(std::isfinite(loop_rate_Hz) && loop_rate_Hz >= 100.0 && loop_rate_Hz <= 10000.0,
          "hexapod.loop_rate_Hz", "must be within [100, 10000] Hz", loop_rate_Hz);
  require(queue >= 1 && queue <= 4096, "hexapod.queue", "must be within [1, 4096]",
          static_cast<double>(queue));
}

HexapodStage::HexapodStage(HexapodStageParams p)
    : p_((p.validate(), std::move(p))),
      stage_(leg_model().model, leg_model().map, p_.stage),
      ring_(p_.queue) {
  // The stage's own period is its trackers' (1 / control_rate_Hz): as many per loop period.
  ticks_per_period_ = std::max(1, static_cast<int>(std::lround(1.0 / (p_.loop_rate_Hz * stage_.tick_s()))));
  next_.traj.emplace(motion::PlatformTransform{}, motion::PlatformTransform{}, p_.stage.move);
  HexapodView v;
  v.measured = stage_.measured_pose();
  v.reference = stage_.reference_pose();
  view_.publish(v);
  loop_ = std::make_unique<runtime::FixedRateLoop>(p_.loop_rate_Hz);
  loop_->add_task("hexapod", 1, [this](const runtime::TickInfo&) { period(); });
}

HexapodStage::~HexapodStage() { stop_loop(); }

void HexapodStage::start() {
  if (thread_.joinable()) return;
  thread_ = std::thread([this] { loop_->run_realtime(~std::uint64_t{0}); });
}

void HexapodStage::stop_loop() {
  if (!thread_.joinable()) return;
  // The flag, not only request_stop(): a run that has not begun yet would clear the request.
  quit_.store(true, std::memory_order_relaxed);
  loop_->request_stop();
  thread_.join();
}

bool HexapodStage::push_move(const motion::PoseTrajectory& checked, std::uint64_t seq) {
  Command c;
  c.traj = checked;
  c.seq = seq;
  return ring_.push(c);
}

void HexapodStage::period() noexcept {
  if (quit_.load(std::memory_order_relaxed)) loop_->request_stop();
  // A stop first: it overtakes every move queued before it (those with a smaller seq).
  const std::uint64_t stop = stop_seq_.load(std::memory_order_acquire);
  if (stop != stop_applied_) {
    stage_.stop();
    if (has_next_ && next_.seq < stop) has_next_ = false;
    while (!has_next_ && ring_.pop(next_)) has_next_ = next_.seq > stop;
    stop_applied_ = stop;
  }
  if (!has_next_ && ring_.pop(next_)) has_next_ = next_.seq > stop_applied_;
  // The next move starts once the present one has ended (it was planned from its goal).
  if (has_next_ && !stage_.moving()) {
    if (stage_.start_move(*next_.traj))
      started_ = next_.seq;
    else
      rejected_ = next_.seq;
    has_next_ = false;
  }
  for (int k = 0; k < ticks_per_period_; ++k) stage_.tick();
  ticks_.fetch_add(1, std::memory_order_relaxed);
  HexapodView v;
  v.measured = stage_.measured_pose();
  v.reference = stage_.reference_pose();
  v.moving = stage_.moving() || has_next_;
  v.at_rest = stage_.at_rest() && !has_next_;
  v.fault = stage_.fault();
  v.started_seq = started_;
  v.rejected_seq = rejected_;
  v.stop_seq = stop_applied_;
  v.time_s = stage_.time_s();
  view_.publish(v);
}

}  // namespace mc::twins
