// The one translation unit that includes OpenCV (its headers are heavy, so they are kept in few places;
// docs/architecture.md). Built only with MC_WITH_OPENCV (src/microcobot/CMakeLists.txt).
#include "microcobot/devices/opencv_camera.h"

#include <chrono>
#include <cstring>
#include <filesystem>
#include <thread>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"

namespace mc::devices {
namespace {

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

  void open(const CameraDeviceParams& params) override {
    close();
    std::error_code ec;
    file_ = !all_digits(source_) && source_.find('!') == std::string::npos &&
            std::filesystem::is_regular_file(source_, ec);
    bool ok = false;
    if (all_digits(source_)) {
      ok = capture_.open(std::stoi(source_), cv::CAP_ANY);
    } else if (source_.find('!') != std::string::npos) {
      ok = capture_.open(source_, cv::CAP_GSTREAMER);
    } else {
      ok = open_named();
    }
    if (!ok || !capture_.isOpened())
      throw InvalidInput("camera: OpenCV cannot open '" + excerpt(source_) + "' (backends: " + backends() +
                         ")");
    if (!file_ && source_.find('!') == std::string::npos) {
      // A live camera is asked for the configured sensor and rate (best effort: it may refuse);
      // a GStreamer pipeline says its own caps (setting them restarts it).
      capture_.set(cv::CAP_PROP_FRAME_WIDTH, params.sensor.width_px);
      capture_.set(cv::CAP_PROP_FRAME_HEIGHT, params.sensor.height_px);
      capture_.set(cv::CAP_PROP_FPS, params.sensor.frame_rate_Hz);
    }
    period_ = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(1.0 / params.sensor.frame_rate_Hz));
    next_ = std::chrono::steady_clock::now();
  }

  void close() override {
    if (capture_.isOpened()) capture_.release();
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
    if (!capture_.read(frame_) || frame_.empty()) {
      if (!file_ || !capture_.set(cv::CAP_PROP_POS_FRAMES, 0) || !capture_.read(frame_) || frame_.empty())
        throw ComputationFailed("camera: '" + excerpt(source_) + "' stopped delivering frames");
    }
    if (frame_.channels() == 3) {
      cv::cvtColor(frame_, converted_, cv::COLOR_BGR2RGB);
    } else if (frame_.channels() == 4) {
      cv::cvtColor(frame_, converted_, cv::COLOR_BGRA2RGB);
    } else {
      converted_ = frame_;
    }
    const int depth = converted_.depth();
    if (depth != CV_8U && depth != CV_16U)
      throw ComputationFailed("camera: '" + excerpt(source_) + "' delivers samples OpenCV calls depth " +
                              std::to_string(depth) + " (8 or 16-bit unsigned expected)");
    const int bits = depth == CV_8U ? 8 : 16;
    out.resize(converted_.cols, converted_.rows, converted_.channels(), bits);
    const std::size_t row = static_cast<std::size_t>(converted_.cols) * converted_.elemSize();
    for (int y = 0; y < converted_.rows; ++y)
      std::memcpy(out.data.data() + static_cast<std::size_t>(y) * row, converted_.ptr(y), row);
    return true;
  }

 private:
  // A file, a device node or a URL, through each stream back-end but gPhoto2. gPhoto2 drives
  // still cameras over USB: for any name it autodetects on the USB bus, which is slow, and
  // libgphoto2 2.5.30 leaks every device list it scans (LeakSanitizer saw 2,500 on one machine).
  bool open_named() {
    for (const cv::VideoCaptureAPIs api : cv::videoio_registry::getStreamBackends()) {
      if (api == cv::CAP_GPHOTO2) continue;
      if (capture_.open(source_, api) && capture_.isOpened()) return true;
    }
    return false;
  }

  static std::string backends() {
    std::string names;
    for (const cv::VideoCaptureAPIs api : cv::videoio_registry::getStreamBackends())
      names += (names.empty() ? "" : ", ") + cv::videoio_registry::getBackendName(api);
    return names;
  }

  std::string source_;
  bool file_ = false;
  cv::VideoCapture capture_;
  cv::Mat frame_, converted_;
  std::chrono::steady_clock::duration period_{};
  std::chrono::steady_clock::time_point next_{};
};

}  // namespace

bool opencv_camera_available() { return true; }

std::unique_ptr<FrameSource> make_opencv_camera(const std::string& source) {
  return std::make_unique<OpenCvCamera>(source);
}

}  // namespace mc::devices
