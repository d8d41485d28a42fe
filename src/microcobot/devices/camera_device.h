#pragma once
/// @file
/// The microscope camera and its focus drive as devices of the platform.
///
/// The camera forms frames off the real-time loop, in a thread of its own at its frame rate:
///
///   loop, every tick   frame_due(t)? -> publish(SceneSnapshot)   (wait-free ring push; a full
///                                                                 ring counts a dropped frame)
///   camera thread      pop snapshot -> FrameSource::capture -> JPEG -> sink(CameraFrame)
///
/// Frame k is due at loop time k / frame_rate_Hz, the middle of its exposure: the loop's
/// snapshot of that tick (positions and velocities, for the motion blur over the exposure) is
/// the scene the frame shows, and the frame carries that time. The loop never waits for the
/// camera: a camera thread that stalls (a slow renderer, a slow consumer) fills its ring, and
/// the frames the loop could not hand over are counted as dropped (tests/platform/
/// camera_device_test.cc proves the loop's ticks and allocations undisturbed).
///
/// A real camera (a FrameSource that does not render the scene) grabs at its own pace; its
/// frames are stamped with the loop time of the grab (the latest snapshot's loop time plus the
/// steady-clock time since) minus half the exposure.
///
/// The camera moves nothing: its safe state is to go on imaging (the operator's eye). It
/// faults when its source fails (a camera unplugged), and the platform then puts every device
/// in its safe state: an operator who cannot see must not drive the slave.
///
/// The focus drive moves the objective along z at a bounded speed between limits and turns the
/// objective turret; its safe state holds where it is.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "microcobot/devices/camera_frame.h"
#include "microcobot/devices/device.h"
#include "microcobot/imaging/camera_params.h"
#include "microcobot/runtime/spsc_ring.h"
#include "microcobot/vision/affine_calibration.h"

namespace mc {
class JpegEncoder;
}

namespace mc::devices {

/// One objective of the turret (vision's: magnification, NA, working distance, wavelength).
using ObjectiveParams = imaging::ObjectiveParams;

/// The microscope camera of the platform: its sensor and illumination (vision's parameters: the
/// image formation's, and a real camera's settings), the objectives of its turret, where it
/// looks, its focus drive, and how its frames are encoded.
struct CameraDeviceParams {
  bool enabled = true;  ///< false: no camera, no focus drive
  /// Sensor: size, pixel pitch, bit depth, exposure (at most one frame period), gain in [1, 16],
  /// noise, frame rate (frames per second of loop time).
  imaging::SensorParams sensor;
  imaging::IlluminationParams illumination;
  /// Objectives on the turret (imaging::objective_table(): 2x to 50x); the pixel size in the
  /// object is pixel_pitch_m / magnification.
  std::vector<ObjectiveParams> objectives = imaging::objective_table();
  int objective = 0;  ///< the turret's position at power-up
  /// World x, y under the optical axis (the image's centre): the middle of the main scenario's
  /// travel, from the gripper's home (-0.2 mm) to the target (2 mm).
  double view_center_x_m = 0.9e-3;
  double view_center_y_m = 0.0;
  /// The focus drive: focal plane height above the substrate, its travel and speed.
  double focus_start_m = 0.0;
  double focus_min_m = -0.5e-3;
  double focus_max_m = 2e-3;
  double focus_speed_m_s = 1e-3;
  /// Pixel <-> stage calibrations measured by `microcobot vision calibrate --save` (at most one
  /// per objective of the turret); published with each frame's state (/camera/state).
  std::vector<vision::StageCalibration> calibrations;
  int jpeg_quality = 85;        ///< 1..100 (libjpeg-turbo's scale)
  int seed = 1;                 ///< the simulated sensor's noise (frame k: seed and k)
  std::size_t ring_frames = 8;  ///< snapshots the loop may queue ahead of the camera thread

  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("sensor", sensor);
    v("illumination", illumination);
    v("objectives", objectives);
    v("objective", objective);
    v("view_center_x_m", view_center_x_m);
    v("view_center_y_m", view_center_y_m);
    v("focus_start_m", focus_start_m);
    v("focus_min_m", focus_min_m);
    v("focus_max_m", focus_max_m);
    v("focus_speed_m_s", focus_speed_m_s);
    v("calibrations", calibrations);
    v("jpeg_quality", jpeg_quality);
    v("seed", seed);
  }
  /// Throws mc::InvalidParams naming the field.
  void validate() const;
  /// Object-side size of a pixel through objective `i` [m].
  double m_per_px(int i) const;
  /// The calibration measured with objective `i`, or null.
  const vision::StageCalibration* calibration(int i) const;
  double frame_rate_Hz() const { return sensor.frame_rate_Hz; }
};

/// What makes the pixels: a renderer of the scene (the simulated microscope) or a real camera.
/// Called on the camera thread only.
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// Opens the device or prepares the renderer (may allocate; throws mc::Error).
  virtual void open(const CameraDeviceParams& params) = 0;
  virtual void close() {}
  /// True when the frame is formed from the snapshot (one frame per snapshot, due at the
  /// camera's rate in loop time); false for a camera that grabs at its own pace.
  virtual bool renders_scene() const = 0;
  /// Forms (or waits for and grabs) one image into `out`, reusing its buffer. False when a
  /// grabbing camera got none within its own wait (a producer that is silent for now: the thread
  /// asks again); a renderer always forms one. Throws mc::Error when the device fails.
  virtual bool capture(const SceneSnapshot& scene, Image& out) = 0;
  /// Nobody looks at the frames (called on the camera thread when it stops asking for them): a
  /// source whose producer works only while read may tell it to rest.
  virtual void idle() {}
  /// A source that receives its frames as JPEG (a remote camera) gives the last captured one's
  /// bytes here, and the camera sends them on as they are: no second encoding, no generation loss.
  /// Null (the default): the camera encodes the image.
  virtual const std::vector<std::uint8_t>* captured_jpeg() const { return nullptr; }
};

/// Counters of the camera (any thread).
struct CameraStats {
  std::uint64_t frames = 0;   ///< delivered to the sink
  std::uint64_t dropped = 0;  ///< due but not handed to the camera thread (its ring was full)
  std::uint64_t skipped = 0;  ///< handed over but overtaken by newer ones before forming
  double last_capture_s = 0.0, last_encode_s = 0.0, last_latency_s = 0.0;
  std::string error;  ///< why the source failed (empty: it has not)
};

class Camera : public Device {
 public:
  using Sink = std::function<void(const CameraFrame&)>;
  /// Throws mc::InvalidParams on bad parameters.
  Camera(std::string name, CameraDeviceParams params, std::unique_ptr<FrameSource> source);
  ~Camera() override;

  const CameraDeviceParams& params() const { return params_; }
  bool renders_scene() const { return source_->renders_scene(); }

  /// Where frames go (called on the camera thread; may be set or changed at any time, but not
  /// from the sink itself). Without a sink no frame is formed: the snapshots are discarded.
  void set_sink(Sink sink);
  /// Whether anyone looks (a client subscribed to the images, a recording): while false no
  /// frame is formed, as without a sink, so that a server nobody watches pays nothing for its
  /// camera. True by default (any thread).
  void set_wanted(bool wanted) noexcept { wanted_.store(wanted, std::memory_order_release); }
  bool wanted() const noexcept { return wanted_.load(std::memory_order_acquire); }
  /// Whether anyone needs the frames as JPEG (a client of the image channel, a JPEG recording,
  /// the DDS image topic); while false a frame carries no JPEG (CameraFrame::jpeg empty) unless
  /// its source gave one, so that the thread does not spend its frame time encoding what only
  /// the vision, the snapshot or an H.264 recording reads raw. True by default (any thread).
  void set_jpeg_wanted(bool wanted) noexcept { jpeg_wanted_.store(wanted, std::memory_order_release); }
  bool jpeg_wanted() const noexcept { return jpeg_wanted_.load(std::memory_order_acquire); }
  /// Settings for the next frames, clamped to their ranges (any thread).
  void set_exposure_s(double exposure_s) noexcept;
  void set_gain(double gain) noexcept;
  double exposure_s() const noexcept { return exposure_s_.load(std::memory_order_relaxed); }
  double gain() const noexcept { return gain_.load(std::memory_order_relaxed); }

  /// Loop side: true when a frame is due at loop time `t_s` (the next frame's mid-exposure has
  /// come); then advances to the next frame. Real-time safe.
  bool frame_due(double t_s) noexcept;
  /// Loop side: hands the scene to the camera thread. Wait-free; false (a dropped frame) when
  /// the camera thread is behind.
  bool publish(const SceneSnapshot& scene) noexcept;

  CameraStats stats() const;
  /// Frames due that the loop could not hand over (wait-free; any thread).
  std::uint64_t dropped() const noexcept { return ring_.dropped(); }

  void update(double dt_s) noexcept override;
  void enter_safe_state() noexcept override {}

 protected:
  void on_configure() override;
  void on_activate() override;
  void on_deactivate() override;

 private:
  void thread_main();
  void deliver(CameraFrame& frame, const SceneSnapshot& scene, std::int64_t t0_ns, JpegEncoder& encoder);

  CameraDeviceParams params_;
  std::unique_ptr<FrameSource> source_;
  runtime::SpscRing<SceneSnapshot> ring_;
  std::atomic<double> exposure_s_, gain_;
  double next_frame_t_s_ = 0.0;  // loop thread
  std::uint64_t next_frame_ = 0;

  std::atomic<bool> running_{false}, failed_{false}, has_sink_{false}, wanted_{true}, jpeg_wanted_{true};
  std::thread thread_;
  std::mutex sink_mutex_;  // the sink (held while it runs: do not set_sink from it)
  Sink sink_;
  mutable std::mutex mutex_;  // the error text and the timings; never the loop
  std::atomic<std::uint64_t> frames_{0}, skipped_{0};
  CameraStats timings_;
  bool opened_ = false;
};

/// The focus drive (objective z) and the objective turret. Commands are clamped to the travel;
/// the drive moves at most focus_speed_m_s. Ignored unless Active; the safe state holds.
class FocusDrive : public Device {
 public:
  /// Throws mc::InvalidParams on bad parameters.
  FocusDrive(std::string name, const CameraDeviceParams& params);

  /// Focal plane height to reach [m]. Real-time safe.
  void command_z_m(double z_m) noexcept;
  /// Turret position; an index out of range is ignored. Real-time safe.
  void command_objective(int index) noexcept;
  double z_m() const { return z_m_; }
  double target_z_m() const { return target_m_; }
  int objective() const { return objective_; }

  void update(double dt_s) noexcept override;
  void enter_safe_state() noexcept override { target_m_ = z_m_; }

 private:
  double min_m_, max_m_, speed_m_s_;
  int objective_count_;
  double z_m_, target_m_;
  int objective_;
};

}  // namespace mc::devices
