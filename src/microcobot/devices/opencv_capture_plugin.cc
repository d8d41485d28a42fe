// The OpenCV camera's plugin: the one translation unit that includes OpenCV's videoio, built as a
// shared module of its own (libmc_opencv_capture.so) that the driver loads on its first camera
// (opencv_capture_plugin.h says why). Nothing here throws across the C interface.
#include "microcobot/devices/opencv_capture_plugin.h"

#include <cstdio>
#include <exception>
#include <memory>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

struct McCapture {
  cv::VideoCapture capture;
  cv::Mat frame, converted;
};

namespace {

void say(char* error, std::size_t size, const std::string& text) {
  if (error && size > 0) std::snprintf(error, size, "%s", text.c_str());
}

std::string backends() {
  std::string names;
  for (const cv::VideoCaptureAPIs api : cv::videoio_registry::getStreamBackends())
    names += (names.empty() ? "" : ", ") + cv::videoio_registry::getBackendName(api);
  return names;
}

// A file, a device node or a URL, through each stream back-end but gPhoto2. gPhoto2 drives still
// cameras over USB: for any name it autodetects on the USB bus, which is slow, and libgphoto2
// 2.5.30 leaks every device list it scans (LeakSanitizer saw 2,500 on one machine).
bool open_named(cv::VideoCapture& capture, const std::string& source) {
  for (const cv::VideoCaptureAPIs api : cv::videoio_registry::getStreamBackends()) {
    if (api == cv::CAP_GPHOTO2) continue;
    if (capture.open(source, api) && capture.isOpened()) return true;
  }
  return false;
}

bool read_frame(McCapture& c, bool rewind) {
  if (c.capture.read(c.frame) && !c.frame.empty()) return true;
  return rewind && c.capture.set(cv::CAP_PROP_POS_FRAMES, 0) && c.capture.read(c.frame) && !c.frame.empty();
}

}  // namespace

extern "C" McCapture* mc_capture_open(const char* source, int kind, int set_format, int width, int height,
                                      double fps, char* error, std::size_t error_size) {
  try {
    auto c = std::make_unique<McCapture>();
    const std::string s = source ? source : "";
    bool ok = false;
    if (kind == kMcCaptureIndex) {
      ok = c->capture.open(std::stoi(s), cv::CAP_ANY);
    } else if (kind == kMcCapturePipeline) {
      ok = c->capture.open(s, cv::CAP_GSTREAMER);
    } else {
      ok = open_named(c->capture, s);
    }
    if (!ok || !c->capture.isOpened()) {
      say(error, error_size, "backends: " + backends());
      return nullptr;
    }
    if (set_format) {
      c->capture.set(cv::CAP_PROP_FRAME_WIDTH, width);
      c->capture.set(cv::CAP_PROP_FRAME_HEIGHT, height);
      c->capture.set(cv::CAP_PROP_FPS, fps);
    }
    return c.release();
  } catch (const std::exception& e) {
    say(error, error_size, std::string("OpenCV: ") + e.what());
    return nullptr;
  }
}

extern "C" int mc_capture_read(McCapture* c, int rewind, McCaptureFrame* frame, char* error,
                               std::size_t error_size) {
  if (!c || !frame) return 0;
  try {
    if (!read_frame(*c, rewind != 0)) return 0;
    if (c->frame.channels() == 3) {
      cv::cvtColor(c->frame, c->converted, cv::COLOR_BGR2RGB);
    } else if (c->frame.channels() == 4) {
      cv::cvtColor(c->frame, c->converted, cv::COLOR_BGRA2RGB);
    } else {
      c->converted = c->frame;
    }
    const int depth = c->converted.depth();
    if (depth != CV_8U && depth != CV_16U) {
      say(error, error_size,
          "delivers samples OpenCV calls depth " + std::to_string(depth) +
              " (8 or 16-bit unsigned expected)");
      return -1;
    }
    if (!c->converted.isContinuous()) c->converted = c->converted.clone();
    *frame = McCaptureFrame{
        c->converted.ptr(0),     c->converted.cols,
        c->converted.rows,       c->converted.channels(),
        depth == CV_8U ? 8 : 16, static_cast<std::size_t>(c->converted.cols) * c->converted.elemSize()};
    return 1;
  } catch (const std::exception& e) {
    say(error, error_size, std::string("OpenCV: ") + e.what());
    return -1;
  }
}

extern "C" void mc_capture_close(McCapture* c) {
  if (!c) return;
  try {
    c->capture.release();
  } catch (const std::exception&) {
    // Closing is best effort: the capture is freed whatever the back-end says.
  }
  delete c;
}
