#include "microcobot/platform/simulated_camera.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>

#include "microcobot/imaging/renderer.h"
#include "microcobot/platform/camera_scene.h"

namespace mc::platform {
namespace {

class SimulatedCamera final : public devices::FrameSource {
 public:
  explicit SimulatedCamera(PlatformConfig config) : config_(std::move(config)) {}

  void open(const devices::CameraDeviceParams& params) override {
    params_ = params;
    // One renderer per objective, made when first turned in (each caches its blurred substrate).
    renderers_.clear();
    renderers_.resize(params_.objectives.size());
  }

  bool renders_scene() const override { return true; }

  bool capture(const devices::SceneSnapshot& scene, devices::Image& out) override {
    CameraScenePose pose;
    pose.tool_x_m = scene.tool_m[0];
    pose.tool_y_m = scene.tool_m[1];
    pose.tool_z_m = scene.tool_m[2];
    pose.opening_m = scene.gripper_opening_m;
    pose.tool_yaw_rad = scene.tool_yaw_rad;
    pose.deflection_x_m = scene.finger_deflection_m[0];
    pose.deflection_y_m = scene.finger_deflection_m[1];
    const double* part = scene.has_beads ? scene.probe_bead_m : scene.part_m;
    pose.part_x_m = part[0];
    pose.part_y_m = part[1];
    pose.part_yaw_rad = scene.has_beads ? 0.0 : scene.part_yaw_rad;
    // The trap's model is planar: the probe bead stays in the dish plane (camera_scene's
    // initial_pose), whatever height the stage's z reports.
    pose.part_z_m = scene.has_beads ? config_.optical_trap.trap.bead_radius_m : part[2];
    pose.vx_m_s = scene.tool_velocity_m_s[0];
    pose.vy_m_s = scene.tool_velocity_m_s[1];
    pose.part_vx_m_s = scene.part_velocity_m_s[0];
    pose.part_vy_m_s = scene.part_velocity_m_s[1];
    pose.seat_x_m = scene.seat_m[0], pose.seat_y_m = scene.seat_m[1];
    pose.seat_yaw_rad = scene.seat_yaw_rad;
    fill_camera_scene(config_, pose, snapshot_);
    snapshot_.t_s = scene.t_s;

    imaging::Renderer& r = renderer(scene.objective);
    imaging::CameraControls controls;
    controls.focus_z_m = scene.focus_z_m;
    controls.exposure_s = scene.exposure_s;
    controls.gain = scene.gain;
    r.render(snapshot_, controls, static_cast<std::uint64_t>(params_.seed), frame_index_++, frame_);

    out.resize(frame_.width, frame_.height, 1, frame_.bit_depth);
    if (frame_.bit_depth <= 8) {
      for (std::size_t i = 0; i < frame_.pixels.size(); ++i)
        out.data[i] = static_cast<std::uint8_t>(frame_.pixels[i]);
    } else {
      // Image keeps deeper samples little-endian: this host's order, one copy.
      static_assert(std::endian::native == std::endian::little);
      std::memcpy(out.data.data(), frame_.pixels.data(), 2 * frame_.pixels.size());
    }
    return true;
  }

 private:
  imaging::Renderer& renderer(int objective) {
    const auto i =
        static_cast<std::size_t>(std::clamp(objective, 0, static_cast<int>(renderers_.size()) - 1));
    if (!renderers_[i]) {
      renderers_[i] = std::make_unique<imaging::Renderer>(renderer_params(params_, static_cast<int>(i)));
    }
    return *renderers_[i];
  }

  PlatformConfig config_;
  devices::CameraDeviceParams params_;
  std::vector<std::unique_ptr<imaging::Renderer>> renderers_;
  imaging::SceneSnapshot snapshot_;
  imaging::Frame frame_;
  std::uint64_t frame_index_ = 0;
};

}  // namespace

std::unique_ptr<devices::FrameSource> make_simulated_camera(const PlatformConfig& config) {
  return std::make_unique<SimulatedCamera>(config);
}

}  // namespace mc::platform
