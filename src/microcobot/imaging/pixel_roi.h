#pragma once
/// @file
/// A region of interest in a frame, shared by the focus measures, the trackers and the
/// localisation bound.

#include "microcobot/imaging/sensor_model.h"

namespace mc::imaging {

/// A rectangle of pixels: columns [x, x + width), rows [y, y + height), row 0 at the top.
struct PixelRoi {
  int x = 0;
  int y = 0;
  int width = 0;
  int height = 0;
};

/// The whole frame.
inline PixelRoi full_roi(const Frame& frame) { return PixelRoi{0, 0, frame.width, frame.height}; }

}  // namespace mc::imaging
