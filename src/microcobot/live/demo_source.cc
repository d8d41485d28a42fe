#include "microcobot/live/demo_source.h"

namespace mc::live {

using cell::PickPlaceOperator;

std::string_view DemoResult::name(Outcome o) {
  switch (o) {
    case Outcome::kNone:
      return "none";
    case Outcome::kRunning:
      return "running";
    case Outcome::kPlaced:
      return "placed";
    case Outcome::kInserted:
      return "inserted";
    case Outcome::kMissed:
      return "missed";
    case Outcome::kGaveUp:
      return "gave_up";
  }
  return "none";
}

void DemoSource::start(std::unique_ptr<PickPlaceOperator> op) {
  op_ = std::move(op);
  const bool demo = op_ != nullptr;
  finished_ = false;
  running_.store(demo);
  phase_.store(0);
  error_m_.store(std::numeric_limits<double>::quiet_NaN());
  duration_s_.store(0.0);
  outcome_.store(static_cast<int>(demo ? DemoResult::Outcome::kRunning : DemoResult::Outcome::kNone),
                 std::memory_order_release);
}

SourceRequest DemoSource::poll(const SourceTick& t) noexcept {
  if (!op_ || finished_) return {};
  op_->act(t.tick);  // the scripted operator moves the simulated masters' hands
  duration_s_.store(t.tick.t_s, std::memory_order_relaxed);
  const auto* gripper = t.platform.simulation().gripper;
  if (gripper != nullptr)
    error_m_.store(gripper->world().placement_error_m(gripper->world_state()), std::memory_order_relaxed);
  if (!op_->done() && !op_->gave_up()) return {Claim::kActive};
  // Finished: it asks for control no more (the arbiter makes every axis hold, the console drives).
  finished_ = true;
  running_.store(false, std::memory_order_relaxed);
  auto outcome = DemoResult::Outcome::kGaveUp;
  if (op_->done() && gripper != nullptr) {
    const auto& w = gripper->world();
    const bool has_hole = w.params().hole_side_m > 0.0;
    if (has_hole && w.inserted(gripper->world_state()))
      outcome = DemoResult::Outcome::kInserted;
    else if (!has_hole && w.placement_error_m(gripper->world_state()) <= tolerance_m_)
      outcome = DemoResult::Outcome::kPlaced;
    else
      outcome = DemoResult::Outcome::kMissed;
  }
  outcome_.store(static_cast<int>(outcome), std::memory_order_release);
  return {};
}

void DemoSource::publish(const SourceTick&) noexcept {
  phase_.store(op_ ? static_cast<int>(op_->phase()) : 0, std::memory_order_relaxed);
  failed_phase_.store(op_ ? static_cast<int>(op_->failed_phase()) : 0, std::memory_order_relaxed);
}

std::string DemoSource::phase_name() const {
  if (!running()) return {};
  return std::string(PickPlaceOperator::name(static_cast<PickPlaceOperator::Phase>(phase_.load())));
}

DemoResult DemoSource::result(bool scene_has_hole) const {
  DemoResult r;
  r.outcome = static_cast<DemoResult::Outcome>(outcome_.load(std::memory_order_acquire));
  r.placement_error_m = error_m_.load(std::memory_order_relaxed);
  r.duration_s = duration_s_.load(std::memory_order_relaxed);
  if (r.outcome == DemoResult::Outcome::kNone) return r;
  // The operator's phase and failed phase are the loop's; read through their atomic copies.
  const auto phase = static_cast<PickPlaceOperator::Phase>(phase_.load());
  const auto failed = static_cast<PickPlaceOperator::Phase>(failed_phase_.load());
  r.phase = std::string(PickPlaceOperator::name(phase));
  switch (r.outcome) {
    case DemoResult::Outcome::kGaveUp:
      r.reason = std::string(PickPlaceOperator::give_up_reason(failed));
      r.phase = std::string(PickPlaceOperator::name(failed));
      break;
    case DemoResult::Outcome::kPlaced:
      r.reason = "the part rests within the placement tolerance of its target";
      break;
    case DemoResult::Outcome::kInserted:
      r.reason = "the pin is down in its hole";
      break;
    case DemoResult::Outcome::kMissed:
      r.reason =
          scene_has_hole ? "the pin is not in its hole" : "the part rests outside the placement tolerance";
      break;
    default:
      break;
  }
  return r;
}

}  // namespace mc::live
