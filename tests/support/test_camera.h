#pragma once
/// @file
/// A frame source for the camera's tests (not a renderer: vision/ forms the real images): a dark
/// field with the part (or probe bead) drawn as a bright square where the snapshot puts it,
/// through the camera's scale (view centre, objective), and its brightness set by the focus
/// (brightest with the focal plane at the part's top) so a test sees what the frame was made
/// of. Registered as the camera driver "test-pattern". The test can make it stall (a slow
/// renderer: capture() waits until released) or fail (a camera unplugged: capture() throws).

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <thread>

#include "microcobot/devices/camera_device.h"
#include "microcobot/platform/driver_registry.h"

namespace mc::test {

struct TestCameraControl {
  std::atomic<bool> stall{false};  ///< capture() waits while set
  std::atomic<bool> fail{false};   ///< capture() throws while set
  std::atomic<int> captures{0};
  double part_top_m = 300e-6;  ///< the focal plane where the square is brightest
};

inline TestCameraControl& test_camera() {
  static TestCameraControl control;
  return control;
}

class TestPatternSource final : public devices::FrameSource {
 public:
  void open(const devices::CameraDeviceParams& params) override { params_ = params; }
  bool renders_scene() const override { return true; }
  bool capture(const devices::SceneSnapshot& scene, devices::Image& out) override {
    TestCameraControl& c = test_camera();
    while (c.stall.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (c.fail.load()) throw std::runtime_error("test camera: unplugged");
    c.captures.fetch_add(1);
    out.resize(params_.sensor.width_px, params_.sensor.height_px, 1, 8);
    std::fill(out.data.begin(), out.data.end(), std::uint8_t{16});
    const double scale = params_.m_per_px(scene.objective);
    const double* p = scene.has_beads ? scene.probe_bead_m : scene.part_m;
    const double cx = (p[0] - params_.view_center_x_m) / scale + 0.5 * params_.sensor.width_px;
    const double cy =
        0.5 * params_.sensor.height_px - (p[1] - params_.view_center_y_m) / scale;  // image y down
    const double half = 0.5 * 300e-6 / scale;
    const double defocus = std::abs(scene.focus_z_m - c.part_top_m);
    const auto level = static_cast<std::uint8_t>(std::clamp(240.0 - defocus * 2e5, 40.0, 240.0));
    for (int y = std::max(0, static_cast<int>(cy - half));
         y < std::min(out.height, static_cast<int>(cy + half)); ++y)
      for (int x = std::max(0, static_cast<int>(cx - half));
           x < std::min(out.width, static_cast<int>(cx + half)); ++x)
        out.data[static_cast<std::size_t>(y) * static_cast<std::size_t>(out.width) +
                 static_cast<std::size_t>(x)] = level;
    return true;
  }

 private:
  devices::CameraDeviceParams params_;
};

/// Registers "test-pattern" once (idempotent).
inline void register_test_camera() {
  static const bool once = [] {
    platform::register_camera("test-pattern", [](const platform::PlatformConfig&) {
      return std::make_unique<TestPatternSource>();
    });
    return true;
  }();
  (void)once;
}

}  // namespace mc::test
