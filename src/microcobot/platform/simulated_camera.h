#pragma once
/// @file
/// The simulated microscope camera (`devices.camera.driver: simulated`): the image formation of
/// vision/ (Renderer) on the platform's scene (camera_scene.h), one frame per snapshot the loop
/// hands over, at the objective, focus, exposure and gain of that snapshot. Deterministic: frame
/// k of a run shows the same noise for the same seed (camera.seed).

#include <memory>

#include "microcobot/devices/camera_device.h"
#include "microcobot/platform/platform_config.h"

namespace mc::platform {

/// The frame source that renders `config`'s microworld (its scene geometry; the moving parts come
/// with each snapshot).
std::unique_ptr<devices::FrameSource> make_simulated_camera(const PlatformConfig& config);

}  // namespace mc::platform
