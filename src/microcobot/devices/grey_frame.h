#pragma once
/// @file
/// A camera image as the vision module's grey frame: the samples as they are (8-bit or deeper,
/// one channel), a colour image's channels averaged. Shared by what measures the frames on the
/// camera thread (the snapshot, the vision positioner).

#include <cstdint>

#include "microcobot/devices/camera_frame.h"
#include "microcobot/imaging/sensor_model.h"

namespace mc::devices {

/// Fills `out` from `image` (its buffer reused: allocates only when it grows). False, `out`
/// untouched, when the image is empty or its data do not match its size.
bool to_grey_frame(const Image& image, std::uint64_t frame_index, imaging::Frame& out);

}  // namespace mc::devices
