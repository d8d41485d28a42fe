#include "microcobot/devices/camera_device.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "microcobot/core/error.h"
#include "microcobot/core/jpeg.h"

namespace mc::devices {
namespace {

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

constexpr double kMinGain = 1.0, kMaxGain = 16.0;
constexpr double kMinExposure_s = 10e-6;

}  // namespace

void CameraDeviceParams::validate() const {
  sensor.validate();
  illumination.validate();
  require(sensor.frame_rate_Hz >= 1.0 && sensor.frame_rate_Hz <= 1000.0, "sensor.frame_rate_Hz",
          "must be within [1, 1000] Hz", sensor.frame_rate_Hz);
  require(sensor.exposure_s >= kMinExposure_s && sensor.exposure_s <= 1.0 / sensor.frame_rate_Hz,
          "sensor.exposure_s", "must be within [10 us, one frame period]", sensor.exposure_s);
  require(sensor.gain >= kMinGain && sensor.gain <= kMaxGain, "sensor.gain", "must be within [1, 16]",
          sensor.gain);
  require(!objectives.empty() && objectives.size() <= 8, "objectives", "must hold 1 to 8 objectives",
          static_cast<double>(objectives.size()));
  for (const ObjectiveParams& o : objectives) o.validate();
  require(objective >= 0 && objective < static_cast<int>(objectives.size()), "objective",
          "must index one of the objectives", objective);
  require(std::isfinite(view_center_x_m) && std::isfinite(view_center_y_m), "view_center_x_m",
          "must be finite");
  require(std::isfinite(focus_min_m) && std::isfinite(focus_max_m) && focus_min_m < focus_max_m,
          "focus_min_m", "must be finite and below focus_max_m", focus_min_m);
  require(focus_start_m >= focus_min_m && focus_start_m <= focus_max_m, "focus_start_m",
          "must be within [focus_min_m, focus_max_m]", focus_start_m);
  require(std::isfinite(focus_speed_m_s) && focus_speed_m_s > 0 && focus_speed_m_s <= 0.1, "focus_speed_m_s",
          "must be within (0, 0.1] m/s", focus_speed_m_s);
  for (std::size_t i = 0; i < calibrations.size(); ++i) {
    const std::string at = "calibrations[" + std::to_string(i) + "]";
    try {
      calibrations[i].validate();
    } catch (const InvalidParams& e) {
      // The item's field, with the list's name before it (the message's constraint kept).
      const std::string what = e.what();
      const auto colon = what.find(": ");
      throw InvalidParams(at + "." + e.field(), colon == std::string::npos ? what : what.substr(colon + 2));
    }
    const bool known = std::any_of(objectives.begin(), objectives.end(), [&](const ObjectiveParams& o) {
      return o.name == calibrations[i].objective;
    });
    require(known, at + ".objective",
            "must name an objective of the turret (" + calibrations[i].objective + ")");
    for (std::size_t j = 0; j < i; ++j)
      require(calibrations[j].objective != calibrations[i].objective, at + ".objective",
              "must not repeat an earlier calibration's objective (" + calibrations[i].objective + ")");
  }
  require(jpeg_quality >= 1 && jpeg_quality <= 100, "jpeg_quality", "must be within [1, 100]", jpeg_quality);
  require(ring_frames >= 2 && ring_frames <= 1024, "ring_frames", "must be within [2, 1024]",
          static_cast<double>(ring_frames));
}

const vision::StageCalibration* CameraDeviceParams::calibration(int i) const {
  if (i < 0 || i >= static_cast<int>(objectives.size())) return nullptr;
  const std::string& name = objectives[static_cast<std::size_t>(i)].name;
  for (const vision::StageCalibration& c : calibrations)
    if (c.objective == name) return &c;
  return nullptr;
}

double CameraDeviceParams::m_per_px(int i) const {
  const auto& o =
      objectives.at(static_cast<std::size_t>(std::clamp(i, 0, static_cast<int>(objectives.size()) - 1)));
  return sensor.pixel_pitch_m / o.magnification;
}

Camera::Camera(std::string name, CameraDeviceParams params, std::unique_ptr<FrameSource> source)
    : Device(std::move(name)),
      params_((params.validate(), std::move(params))),
      source_(std::move(source)),
      ring_(params_.ring_frames),
      exposure_s_(params_.sensor.exposure_s),
      gain_(params_.sensor.gain) {
  if (!source_) throw InvalidParams("camera", "has no frame source");
}

Camera::~Camera() {
  on_deactivate();
  if (opened_) source_->close();
}

void Camera::set_sink(Sink sink) {
  std::lock_guard lock(sink_mutex_);
  has_sink_.store(static_cast<bool>(sink), std::memory_order_release);
  sink_ = std::move(sink);
}

void Camera::set_exposure_s(double exposure_s) noexcept {
  if (!std::isfinite(exposure_s)) return;
  exposure_s_.store(std::clamp(exposure_s, kMinExposure_s, 1.0 / params_.sensor.frame_rate_Hz),
                    std::memory_order_relaxed);
}

void Camera::set_gain(double gain) noexcept {
  if (!std::isfinite(gain)) return;
  gain_.store(std::clamp(gain, kMinGain, kMaxGain), std::memory_order_relaxed);
}

bool Camera::frame_due(double t_s) noexcept {
  if (t_s + 1e-12 < next_frame_t_s_) return false;
  // After a pause (a scene rebuilt, a slow start) the next frame is the next one on the grid.
  const double period = 1.0 / params_.sensor.frame_rate_Hz;
  ++next_frame_;
  next_frame_t_s_ = static_cast<double>(next_frame_) * period;
  if (next_frame_t_s_ <= t_s) {
    next_frame_ = static_cast<std::uint64_t>(std::floor(t_s / period)) + 1;
    next_frame_t_s_ = static_cast<double>(next_frame_) * period;
  }
  return true;
}

bool Camera::publish(const SceneSnapshot& scene) noexcept {
  if (!active()) return false;
  if (!wanted()) return true;  // nobody looks: nothing to hand over, nothing dropped
  return ring_.push(scene);
}

CameraStats Camera::stats() const {
  std::lock_guard lock(mutex_);
  CameraStats s = timings_;
  s.frames = frames_.load(std::memory_order_relaxed);
  s.dropped = ring_.dropped();
  s.skipped = skipped_.load(std::memory_order_relaxed);
  return s;
}

void Camera::update(double) noexcept {
  // The camera thread cannot fault the device itself (the lifecycle is the loop's): its
  // failure is seen here, at the next tick.
  if (failed_.load(std::memory_order_acquire) && state() != Lifecycle::kFault) fault();
}

void Camera::on_configure() {
  on_deactivate();
  failed_.store(false);
  if (opened_) source_->close();
  opened_ = false;
  source_->open(params_);
  opened_ = true;
  std::lock_guard lock(mutex_);
  timings_.error.clear();
}

void Camera::on_activate() {
  SceneSnapshot stale;
  while (ring_.pop(stale)) {
  }
  running_.store(true);
  thread_ = std::thread([this] { thread_main(); });
}

void Camera::on_deactivate() {
  running_.store(false);
  if (thread_.joinable()) thread_.join();
}

void Camera::thread_main() {
  CameraFrame frame;
  frame.image.data.reserve(static_cast<std::size_t>(params_.sensor.width_px) *
                           static_cast<std::size_t>(params_.sensor.height_px) *
                           (params_.sensor.bit_depth > 8 ? 2u : 1u));
  SceneSnapshot scene, newer;
  bool have_scene = false, idle = false;
  double last_t_mid = -1.0;
  try {
    JpegEncoder encoder;
    while (running_.load(std::memory_order_acquire)) {
      if (!has_sink_.load(std::memory_order_acquire) || !wanted()) {
        // Nobody looks: no frame is formed (a batch run, a server without viewers pay nothing).
        if (!idle) source_->idle();
        idle = true;
        while (ring_.pop(newer)) {
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        continue;
      }
      idle = false;
      if (source_->renders_scene()) {
        // One frame per snapshot; when several wait (the thread fell behind), the newest wins.
        if (!ring_.pop(scene)) {
          std::this_thread::sleep_for(std::chrono::microseconds(500));
          continue;
        }
        while (ring_.pop(newer)) {
          scene = newer;
          skipped_.fetch_add(1, std::memory_order_relaxed);
        }
        const std::int64_t t0 = steady_ns();
        if (!source_->capture(scene, frame.image)) continue;
        frame.t_mid_s = scene.t_s;
        deliver(frame, scene, t0, encoder);
      } else {
        // A real camera paces itself; the snapshots only tell the loop's time and state.
        while (ring_.pop(newer)) {
          scene = newer;
          have_scene = true;
        }
        const std::int64_t t0 = steady_ns();
        if (!source_->capture(scene, frame.image)) continue;
        const std::int64_t t1 = steady_ns();
        const double exposure = exposure_s_.load(std::memory_order_relaxed);
        // The newest snapshot maps the wall clock onto the loop's. A loop that fell behind the
        // wall clock and catches up moves that map back by its lag; a frame grabbed after another
        // is still never stamped before it.
        const double mapped =
            have_scene ? scene.t_s + 1e-9 * static_cast<double>(t1 - scene.steady_ns) - 0.5 * exposure : 0.0;
        frame.t_mid_s = std::max(mapped, last_t_mid + 1e-6);
        last_t_mid = frame.t_mid_s;
        deliver(frame, scene, t0, encoder);
      }
    }
  } catch (const std::exception& e) {
    {
      std::lock_guard lock(mutex_);
      timings_.error = e.what();
    }
    failed_.store(true, std::memory_order_release);
  }
}

void Camera::deliver(CameraFrame& frame, const SceneSnapshot& scene, std::int64_t t0_ns,
                     JpegEncoder& encoder) {
  const std::int64_t t1 = steady_ns();
  const Image& img = frame.image;
  if (const std::vector<std::uint8_t>* jpeg = source_->captured_jpeg())
    frame.jpeg.assign(jpeg->begin(), jpeg->end());
  else if (jpeg_wanted())
    encoder.encode({img.width, img.height, img.channels, img.bit_depth, img.data}, params_.jpeg_quality,
                   frame.jpeg);
  else
    frame.jpeg.clear();  // nobody needs it: the frame's time goes to forming the next
  const std::int64_t t2 = steady_ns();
  const int objective = std::clamp(scene.objective, 0, static_cast<int>(params_.objectives.size()) - 1);
  const ObjectiveParams& o = params_.objectives[static_cast<std::size_t>(objective)];
  frame.sequence = frames_.load(std::memory_order_relaxed);
  frame.exposure_s =
      source_->renders_scene() ? scene.exposure_s : exposure_s_.load(std::memory_order_relaxed);
  frame.gain = source_->renders_scene() ? scene.gain : gain_.load(std::memory_order_relaxed);
  frame.objective = objective;
  frame.objective_name = o.name;
  frame.magnification = o.magnification;
  frame.working_distance_m = o.working_distance_m;
  frame.m_per_px = params_.sensor.pixel_pitch_m / o.magnification;
  frame.focus_z_m = scene.focus_z_m;
  frame.view_center_m[0] = params_.view_center_x_m;
  frame.view_center_m[1] = params_.view_center_y_m;
  for (int i = 0; i < 3; ++i) frame.tool_m[i] = scene.tool_m[i];
  frame.gripper_opening_m = scene.gripper_opening_m;
  frame.gripper_free_opening_m = scene.gripper_free_opening_m;
  frame.tool_yaw_rad = scene.tool_yaw_rad;
  frame.capture_s = 1e-9 * static_cast<double>(t1 - t0_ns);
  frame.encode_s = 1e-9 * static_cast<double>(t2 - t1);
  frame.latency_s = source_->renders_scene() ? 1e-9 * static_cast<double>(t2 - scene.steady_ns) : 0.0;
  {
    std::lock_guard lock(sink_mutex_);
    if (sink_) sink_(frame);
  }
  frames_.fetch_add(1, std::memory_order_relaxed);
  std::lock_guard lock(mutex_);
  timings_.last_capture_s = frame.capture_s;
  timings_.last_encode_s = frame.encode_s;
  timings_.last_latency_s = frame.latency_s;
}

FocusDrive::FocusDrive(std::string name, const CameraDeviceParams& params)
    : Device(std::move(name)),
      min_m_((params.validate(), params.focus_min_m)),
      max_m_(params.focus_max_m),
      speed_m_s_(params.focus_speed_m_s),
      objective_count_(static_cast<int>(params.objectives.size())),
      z_m_(params.focus_start_m),
      target_m_(params.focus_start_m),
      objective_(params.objective) {}

void FocusDrive::command_z_m(double z_m) noexcept {
  if (!active() || !std::isfinite(z_m)) return;
  target_m_ = std::clamp(z_m, min_m_, max_m_);
}

void FocusDrive::command_objective(int index) noexcept {
  if (!active() || index < 0 || index >= objective_count_) return;
  objective_ = index;
}

void FocusDrive::update(double dt_s) noexcept {
  if (!active()) return;
  // A rate-limited move to the target: the motor's speed bounds the step.
  const double step = speed_m_s_ * dt_s;
  z_m_ += std::clamp(target_m_ - z_m_, -step, step);
}

}  // namespace mc::devices
