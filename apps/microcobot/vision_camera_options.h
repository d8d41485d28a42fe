#pragma once
// The options every `vision` processing command shares (calibrate, track, autofocus): the scene,
// the objective, the noise seed, the template's side; and the template's window in the frame.

#include <cstdint>
#include <string>

#include <CLI/CLI.hpp>

#include "microcobot/imaging/camera_params.h"
#include "microcobot/imaging/pixel_roi.h"

namespace mc::cli {

struct CameraOptions {
  std::string scene = "pick-place";
  std::string objective = "10x";
  std::uint64_t seed = 1;
  int template_px = 96;
};

void add_camera_options(CLI::App& cmd, CameraOptions& o);

/// The camera with the chosen objective (an unknown one: mc::UsageError naming --objective).
imaging::CameraParams camera_for(const CameraOptions& o);

/// The template: `side` square centred on `u, v`, inside the frame (mc::InvalidInput naming
/// --template-px otherwise: exit 3).
imaging::PixelRoi centred_roi(double u, double v, int side, const imaging::CameraParams& cam);

}  // namespace mc::cli
