#include "microcobot/drivers/pi_hexapod.h"

#include <cmath>

#include "microcobot/core/error.h"
#include "microcobot/drivers/gcs2_codec.h"

namespace mc::drivers {
namespace {

/// The trajectory's start against the held pose: the simulated positioner's tolerance
/// (motion::ParallelStage::start_move), every entry of R and d.
constexpr double kStartTolerance = 1e-9;

bool same_pose(const motion::PlatformTransform& a, const motion::PlatformTransform& b) noexcept {
  return (a.R - b.R).cwiseAbs().maxCoeff() <= kStartTolerance &&
         (a.d - b.d).cwiseAbs().maxCoeff() <= kStartTolerance;
}

}  // namespace

PiHexapod::PiHexapod(std::string name, std::shared_ptr<PiHexapodController> controller,
                     const motion::ParallelGeometryParams& geometry)
    : ParallelPositioner(std::move(name)), controller_(std::move(controller)), kinematics_(geometry) {}

void PiHexapod::on_configure() {
  controller_->configure();
  // After a reconnect the bus counts every move and stop asked before as done (the handshake drops
  // what the faulted bus left in the ring); on a healthy bus a stop under way still settles.
  status_ = controller_->status();
}

void PiHexapod::update(double /*dt_s*/) noexcept {
  status_ = controller_->status();
  if (controller_->faulted() && state() != devices::Lifecycle::kFault) fault();
}

bool PiHexapod::moving() const noexcept {
  if (controller_->faulted()) return false;  // the bus is gone: #24 was sent if it could be; nothing is known
  return move_seq_ > status_.move_done || stop_seq_ > status_.stop_done || status_.moving;
}

bool PiHexapod::start_move(const motion::PoseTrajectory& checked) noexcept {
  if (!active() || controller_->faulted() || !controller_->fresh() || !at_rest()) return false;
  if (!same_pose(checked.start(), status_.held)) return false;
  HexapodMove m;
  m.seq = seq_ + 1;
  m.goal = checked.goal();
  m.speed_mm_s = checked.limits().max_speed_m_s * gcs2::kMmPerM;
  if (!controller_->push_move(m)) return false;
  seq_ = m.seq;
  move_seq_ = m.seq;
  return true;
}

void PiHexapod::stop() noexcept {
  // Already holding: the held pose stays exactly what it is, so that a move planned from it still
  // starts (a stop would hold again where the sensors read, a nanometre away), as the simulated
  // positioner does (motion::ParallelStage::stop).
  if (moving()) send_stop();
}

void PiHexapod::send_stop() noexcept {
  if (stop_seq_ > status_.stop_done) return;  // one stop at a time: it drops every move before it
  stop_seq_ = ++seq_;
  controller_->request_stop(stop_seq_);
}

std::unique_ptr<devices::ParallelPositioner> make_pi_hexapod(const platform::PlatformConfig& config) {
  Connection c;
  PiHexapodParams params;
  try {
    c = parse_connection(config.parallel_positioner.connection, "pi-hexapod");
    params = pi_hexapod_params(c);
  } catch (const InvalidParams& e) {
    // The connection's parser names the Cartesian drivers' key; this one is the positioner's.
    const std::string f = e.field(), cartesian = "devices.connection";
    if (f.rfind(cartesian, 0) != 0) throw;
    throw InvalidParams(
        "parallel_positioner.connection" + f.substr(cartesian.size()),
        std::string(e.what()).substr(std::string("invalid parameter ").size() + f.size() + 2));
  }
  auto controller = std::make_shared<PiHexapodController>(c, params);
  return std::make_unique<PiHexapod>("pi_hexapod", std::move(controller),
                                     config.parallel_positioner.geometry);
}

}  // namespace mc::drivers
