#pragma once
// Scenes and a small camera for the focus tests (sharpness, depth from focus, autofocus): the
// physics of defocus does not depend on the pixel count, so 320 x 256 sensors keep them fast.

#include <cstdint>
#include <string>

#include "microcobot/imaging/renderer.h"
#include "microcobot/vision/sharpness.h"

namespace mc::vision::testing {

inline imaging::CameraParams focus_camera(const std::string& objective) {
  imaging::CameraParams c;
  c.objective = imaging::objective_by_name(objective);
  c.sensor.width_px = 320;
  c.sensor.height_px = 256;
  return c;
}

/// The central 256 x 192 pixels of the 320 x 256 frame.
inline constexpr imaging::PixelRoi kFocusRoi{32, 32, 256, 192};

/// The default lapped substrate (texture grain 2 um, 4 octaves), surface at z = 0.
inline imaging::SceneSnapshot substrate_scene(std::uint64_t texture_seed) {
  imaging::SceneSnapshot s;
  s.substrate.texture_seed = texture_seed;
  return s;
}

/// A 300 um brass block on the substrate, top face at `z_top_m`, its left edge through the view's
/// centre (the ROI holds the edge: the top face itself is uniform).
inline imaging::SceneSnapshot part_scene(std::uint64_t texture_seed, double z_top_m) {
  imaging::SceneSnapshot s = substrate_scene(texture_seed);
  imaging::Part p;
  p.size_x_m = p.size_y_m = 300e-6;
  p.x_m = 150e-6;
  p.z_top_m = z_top_m;
  s.parts.push_back(p);
  return s;
}

/// A camera taking noisy frames (each a new frame index) and measuring them.
class FocusCamera {
 public:
  FocusCamera(const std::string& objective, imaging::SceneSnapshot scene, std::uint64_t noise_seed = 1)
      : renderer_(focus_camera(objective)), scene_(std::move(scene)), seed_(noise_seed) {
    controls_ = renderer_.default_controls();
  }
  const imaging::OpticsFigures& figures() const { return renderer_.figures(); }
  imaging::CameraControls& controls() { return controls_; }
  const imaging::Frame& frame_at(double focus_z_m) {
    controls_.focus_z_m = focus_z_m;
    renderer_.render(scene_, controls_, seed_, index_++, frame_);
    return frame_;
  }
  double measure(double focus_z_m, FocusMetric metric, const imaging::PixelRoi& roi = kFocusRoi) {
    return sharpness(frame_at(focus_z_m), roi, metric);
  }
  int frames() const { return static_cast<int>(index_); }

 private:
  imaging::Renderer renderer_;
  imaging::SceneSnapshot scene_;
  std::uint64_t seed_;
  imaging::CameraControls controls_;
  imaging::Frame frame_;
  std::uint64_t index_ = 0;
};

}  // namespace mc::vision::testing
