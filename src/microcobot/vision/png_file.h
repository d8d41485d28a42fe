#pragma once
/// @file
/// A camera frame as a PNG file (libpng): 8-bit grey for 8-bit frames, 16-bit grey otherwise
/// (values as they are, not scaled: a 12-bit frame spans 0..4095 of the 16-bit range, and its
/// sBIT chunk says 12 significant bits). Written through a staged file: never half-written.

#include <filesystem>
#include <string>

#include "microcobot/vision/sensor_model.h"

namespace mc::vision {

/// The PNG bytes of `frame`. Throws ComputationFailed if libpng fails.
std::string encode_png(const Frame& frame);
/// Writes `frame` to `path` (temporary name, renamed when complete). Throws InvalidInput naming
/// `path` when it cannot be written.
void write_png(const std::filesystem::path& path, const Frame& frame);

}  // namespace mc::vision
