#include "microcobot/live/live_looker.h"

#include <chrono>
#include <exception>
#include <string_view>

#include "microcobot/platform/camera_scene.h"

namespace mc::live {

using cell::AssemblyTask;

namespace {

// A built-in channel (0 where the platform does not record it: the samples are zero-filled).
double channel(const platform::TelemetrySample& s, std::string_view name) {
  return s[platform::telemetry_channel_index(name)];
}

}  // namespace

LiveLooker::LiveLooker(const cell::CellCameraParams& camera, const platform::PlatformConfig& config,
                       const LiveTaskParams& task_params, LiveTask& task, LatestSample latest)
    : params_(camera), config_(config), task_params_(task_params), task_(task), latest_(std::move(latest)) {
  camera_ = std::make_unique<cell::CellCamera>(params_, config_);
  thread_ = std::thread([this] { run(); });
}

LiveLooker::~LiveLooker() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

cell::PinSighting LiveLooker::look(AssemblyTask::Look kind, const platform::TelemetrySample& s) {
  const platform::CameraScenePose truth = platform::pose_from_telemetry(s, nullptr, 0.0);
  const auto& w = config_.world;
  const cell::PinModel pin{w.part_side_m, w.height_m()};
  const auto& goal = task_params_.goal;
  switch (kind) {
    case AssemblyTask::Look::kSlot:
      return camera_->look_slot(truth, pin, goal.part_m, goal.part_yaw_rad);
    case AssemblyTask::Look::kBore:
      return camera_->look_bore(truth, goal.target_m, goal.target_yaw_rad);  // where its drawing puts it
    case AssemblyTask::Look::kHeld: {
      // The tool point as the stage's sensors give it; the pin's top where the grasp left it.
      const Eigen::Vector3d tool(channel(s, "measured_x_m"), channel(s, "measured_y_m"),
                                 channel(s, "measured_z_m"));
      const double grasp_z = goal.hole_depth_m + task_params_.task.grip_above_m;
      return camera_->look_held(truth, pin, tool, channel(s, "measured_theta_rad"),
                                tool.z() - grasp_z + pin.height_m);
    }
    case AssemblyTask::Look::kAlign: {  // over the bore's station, where the bore look looked from
      const Eigen::Vector3d tool(channel(s, "measured_x_m"), channel(s, "measured_y_m"),
                                 channel(s, "measured_z_m"));
      const double grasp_z = goal.hole_depth_m + task_params_.task.grip_above_m;
      return camera_->look_align(truth, pin, goal.target_m, task_.target_m(), tool,
                                 channel(s, "measured_theta_rad"), tool.z() - grasp_z + pin.height_m);
    }
    case AssemblyTask::Look::kPlaced:  // where the task aimed: the bore as the camera saw it
      return camera_->look_placed(truth, pin, goal.target_m, task_.target_m(), goal.target_yaw_rad,
                                  pin.height_m - goal.hole_depth_m);
    case AssemblyTask::Look::kNone:
      break;
  }
  return {};
}

void LiveLooker::run() {
  using namespace std::chrono_literals;
  std::uint64_t answered = 0;
  while (!stop_.load()) {
    std::this_thread::sleep_for(10ms);
    const LiveTask::LookRequest r = task_.look_request();
    if (r.look == AssemblyTask::Look::kNone || r.seq == answered) continue;
    // The exposure: the task holds while it passes (interruptible by the stop).
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(params_.look_s);
    while (!stop_.load() && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(5ms);
    platform::TelemetrySample sample;
    if (stop_.load() || !latest_(sample)) continue;
    AssemblyTask::Sighting sighting;
    try {
      const cell::PinSighting seen = look(r.look, sample);
      sighting.found = seen.found;
      sighting.part_m = seen.part_m;
      sighting.yaw_rad = seen.yaw_rad;
      sighting.error_m = seen.error_m;
      sighting.converged = seen.converged;
    } catch (const std::exception&) {
      sighting.found = false;  // nothing seen: the task goes on as without a camera (verify: fails)
    }
    if (task_.deliver(r.seq, sighting)) {
      answered = r.seq;
      looks_.fetch_add(1, std::memory_order_relaxed);
    }
  }
}

}  // namespace mc::live
