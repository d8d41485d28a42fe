#pragma once
/// @file
/// A camera frame as a PNG file (libpng): 8-bit grey for 8-bit frames, 16-bit grey otherwise
/// (values as they are, not scaled: a 12-bit frame spans 0..4095 of the 16-bit range, and its
/// sBIT chunk says 12 significant bits). Written through a staged file: never half-written.

#include <filesystem>
#include <string>

#include "microcobot/imaging/sensor_model.h"

namespace mc::imaging {

/// The PNG bytes of `frame`. Throws ComputationFailed if libpng fails.
std::string encode_png(const Frame& frame);
/// The PNG bytes of `frame` with a servoed feature marked by a dark cross (+-8 px) at
/// `feature_px` and its target by a bright one (+-12 px) at `target_px` (u, v: column, row): the
/// overlays of the visual servo's reports. Marks outside the frame are clipped.
std::string encode_marked_png(const Frame& frame, double feature_u_px, double feature_v_px,
                              double target_u_px, double target_v_px);
/// Writes `frame` to `path` (temporary name, renamed when complete). Throws InvalidInput naming
/// `path` when it cannot be written.
void write_png(const std::filesystem::path& path, const Frame& frame);

}  // namespace mc::imaging
