// The OpenCV camera driver: OpenCV itself is in the plugin (opencv_capture_plugin.h says why), which
// this file loads with dlopen on the first camera it opens. The plugin's path is fixed when CMake
// configures (MC_OPENCV_CAPTURE_PLUGIN, in the build tree beside the libraries); a build without
// MC_WITH_OPENCV has no plugin there, and the driver is then absent.
#include "microcobot/devices/opencv_camera.h"

#include <dlfcn.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <thread>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "microcobot/devices/opencv_capture_plugin.h"

namespace mc::devices {
namespace {

struct Plugin {
  McCaptureOpenFn open;
  McCaptureReadFn read;
  McCaptureCloseFn close;
};

// Loaded once and kept for the process's life: unloading it while a camera thread may still be in
// its code would unmap that code. A failed load throws, and the next camera tries again.
const Plugin& plugin() {
  static const Plugin loaded = [] {
    void* handle = dlopen(MC_OPENCV_CAPTURE_PLUGIN, RTLD_NOW | RTLD_LOCAL);
    if (!handle)
      throw InvalidInput(std::string("camera: the OpenCV driver's plugin cannot be loaded: ") + dlerror());
    Plugin p{reinterpret_cast<McCaptureOpenFn>(dlsym(handle, "mc_capture_open")),
             reinterpret_cast<McCaptureReadFn>(dlsym(handle, "mc_capture_read")),
             reinterpret_cast<McCaptureCloseFn>(dlsym(handle, "mc_capture_close"))};
    if (!p.open || !p.read || !p.close)
      throw InvalidInput(std::string("camera: '") + MC_OPENCV_CAPTURE_PLUGIN +
                         "' is not this build's OpenCV plugin (a function is missing)");
    return p;
  }();
  return loaded;
}

bool all_digits(const std::string& s) {
  return !s.empty() && s.size() < 4 && s.find_first_not_of("0123456789") == std::string::npos;
}

class OpenCvCamera final : public FrameSource {
 public:
  explicit OpenCvCamera(std::string source) : source_(std::move(source)) {
    if (source_.empty())
      throw InvalidParams("devices.camera.source",
                          "the opencv driver needs a source: a device index, a device or video file, or a "
                          "GStreamer pipeline");
  }
  ~OpenCvCamera() override { close(); }
  OpenCvCamera(const OpenCvCamera&) = delete;
  OpenCvCamera& operator=(const OpenCvCamera&) = delete;

  void open(const CameraDeviceParams& params) override {
    close();
    const bool pipeline = source_.find('!') != std::string::npos;
    std::error_code ec;
    file_ = !all_digits(source_) && !pipeline && std::filesystem::is_regular_file(source_, ec);
    const int kind = all_digits(source_) ? kMcCaptureIndex : pipeline ? kMcCapturePipeline : kMcCaptureNamed;
    // A live camera is asked for the configured sensor and rate (best effort: it may refuse); a
    // GStreamer pipeline says its own caps (setting them restarts it).
    const bool set_format = !file_ && !pipeline;
    char error[512] = "";
    capture_ = plugin().open(source_.c_str(), kind, set_format ? 1 : 0, params.sensor.width_px,
                             params.sensor.height_px, params.sensor.frame_rate_Hz, error, sizeof error);
    if (!capture_)
      throw InvalidInput("camera: OpenCV cannot open '" + excerpt(source_) + "' (" + error + ")");
    period_ = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(1.0 / params.sensor.frame_rate_Hz));
    next_ = std::chrono::steady_clock::now();
  }

  void close() override {
    if (capture_) plugin().close(capture_);
    capture_ = nullptr;
  }

  bool renders_scene() const override { return false; }

  bool capture(const SceneSnapshot&, Image& out) override {
    if (file_) {
      // A file is played at the camera's rate (a device paces itself), looped at its end.
      next_ += period_;
      const auto now = std::chrono::steady_clock::now();
      if (next_ < now) next_ = now;
      std::this_thread::sleep_until(next_);
    }
    McCaptureFrame frame{};
    char error[512] = "";
    const int read = capture_ ? plugin().read(capture_, file_ ? 1 : 0, &frame, error, sizeof error) : 0;
    if (read == 0) throw ComputationFailed("camera: '" + excerpt(source_) + "' stopped delivering frames");
    if (read < 0) throw ComputationFailed("camera: '" + excerpt(source_) + "' " + error);
    out.resize(frame.cols, frame.rows, frame.channels, frame.bits);
    for (int y = 0; y < frame.rows; ++y)
      std::memcpy(out.data.data() + static_cast<std::size_t>(y) * frame.row_bytes,
                  frame.data + static_cast<std::size_t>(y) * frame.row_bytes, frame.row_bytes);
    return true;
  }

 private:
  std::string source_;
  bool file_ = false;
  McCapture* capture_ = nullptr;
  std::chrono::steady_clock::duration period_{};
  std::chrono::steady_clock::time_point next_{};
};

}  // namespace

bool opencv_camera_available() {
  std::error_code ec;
  return std::filesystem::is_regular_file(MC_OPENCV_CAPTURE_PLUGIN, ec);
}

std::unique_ptr<FrameSource> make_opencv_camera(const std::string& source) {
  if (!opencv_camera_available())
    throw InvalidParams("devices.camera.driver",
                        "'opencv': this build has no OpenCV (install libopencv-videoio-dev, then cmake "
                        "-DMC_WITH_OPENCV=ON; make test does both)");
  return std::make_unique<OpenCvCamera>(source);
}

}  // namespace mc::devices
