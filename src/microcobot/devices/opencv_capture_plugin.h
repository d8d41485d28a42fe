#pragma once
/// @file
/// The C interface between the OpenCV camera driver (opencv_camera.cc, in mc_devices) and the
/// plugin that holds OpenCV's videoio (opencv_capture_plugin.cc, built as
/// libmc_opencv_capture.so when CMake's MC_WITH_OPENCV is on), which the driver loads with dlopen
/// when it first opens a camera. videoio brings about 240 shared libraries (GStreamer, FFmpeg,
/// gPhoto2, GDAL through imgcodecs) whose loading and initialisation cost a process about 0.3 s at
/// its start; as a plugin, only a process that opens a real camera pays it, not every command,
/// test and Python session. A C interface keeps exceptions and C++ types from crossing the
/// boundary: each call reports a failure as a return value and a message.

#include <cstddef>

extern "C" {

/// An open VideoCapture with its last frame (the plugin's own type).
struct McCapture;

/// A frame as the plugin holds it until the next read: `rows` rows of `row_bytes`, samples of
/// `bits` (8 or 16, unsigned), 1 channel (grey) or 3 (RGB order).
struct McCaptureFrame {
  const unsigned char* data;
  int cols, rows, channels, bits;
  std::size_t row_bytes;
};

/// How `source` is opened: a device index, a GStreamer pipeline, or a name (a file, a device node,
/// a URL) tried on each stream back-end but gPhoto2.
enum McCaptureSource { kMcCaptureIndex = 0, kMcCapturePipeline = 1, kMcCaptureNamed = 2 };

/// Opens `source`; with `set_format` asks it for width x height at fps (a live camera, best
/// effort). Returns null on failure, with the back-ends tried (or OpenCV's message) in `error`.
McCapture* mc_capture_open(const char* source, int kind, int set_format, int width, int height, double fps,
                           char* error, std::size_t error_size);

/// Reads the next frame, converted to RGB or grey; with `rewind`, a source at its end is read again
/// from its first frame (a video file played in a loop). Returns 1 with a frame, 0 when the source
/// delivered none, -1 on a frame it cannot convert (the reason in `error`).
int mc_capture_read(McCapture* capture, int rewind, McCaptureFrame* frame, char* error,
                    std::size_t error_size);

/// Releases the source and frees `capture` (null is allowed).
void mc_capture_close(McCapture* capture);

/// The signatures, for the driver's dlsym.
using McCaptureOpenFn = decltype(&mc_capture_open);
using McCaptureReadFn = decltype(&mc_capture_read);
using McCaptureCloseFn = decltype(&mc_capture_close);
}
