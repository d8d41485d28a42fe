#pragma once
/// @file
/// The cell camera's looks for the live task (`serve --cell --cell-camera`: the task
/// verified live by the camera): a thread beside the loop that answers the looks the task asks for
/// (LiveTask::look_request()). For each request it lets `look_s` pass (the exposure: the task
/// holds meanwhile), takes the latest telemetry sample (the simulation's truth renders the frames;
/// the stage's sensors give the tool point the held look measures from), renders and measures with
/// cell::CellCamera, and hands the sighting back (LiveTask::deliver()). Rendering a look takes a
/// few hundred milliseconds: never on the loop. A look that throws (a pin out of the field) is a
/// sighting of nothing.

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "microcobot/cell/cell_camera.h"
#include "microcobot/live/live_task.h"
#include "microcobot/platform/platform.h"

namespace mc::live {

class LiveLooker {
 public:
  /// The latest telemetry sample into `out`; false when there is none yet. Called on the looker's
  /// thread.
  using LatestSample = std::function<bool(platform::TelemetrySample& out)>;

  /// Starts the thread. `config`'s world is the scene (the pin's side and height); `task` must
  /// outlive this object. Throws mc::InvalidParams (the camera's parameters).
  LiveLooker(const cell::CellCameraParams& camera, const platform::PlatformConfig& config,
             const LiveTaskParams& task_params, LiveTask& task, LatestSample latest);
  ~LiveLooker();  ///< stops and joins the thread
  LiveLooker(const LiveLooker&) = delete;
  LiveLooker& operator=(const LiveLooker&) = delete;

  /// Looks answered since the start. Any thread.
  int looks() const noexcept { return looks_.load(std::memory_order_relaxed); }

 private:
  void run();
  cell::PinSighting look(cell::AssemblyTask::Look kind, const platform::TelemetrySample& s);

  cell::CellCameraParams params_;
  platform::PlatformConfig config_;
  LiveTaskParams task_params_;
  LiveTask& task_;
  LatestSample latest_;
  std::unique_ptr<cell::CellCamera> camera_;
  std::atomic<bool> stop_{false};
  std::atomic<int> looks_{0};
  std::thread thread_;
};

}  // namespace mc::live
