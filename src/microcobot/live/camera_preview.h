#pragma once

/// The console's view of the camera: each frame binned down to the microscope panel's
/// size and encoded as its own JPEG, published as /camera/preview/compressed beside the full
/// frame. A 1280 x 1024 frame is four times the pixels of the 640 px panel: the browser decoded
/// it, then threw three quarters away, and without a GPU that decode was what kept the page
/// 0.5-2.8 s behind the scene (docs/benchmarks.md, "Camera device"). Foxglove clients and the
/// recording keep the full frame.

#include <cstdint>
#include <vector>

#include "microcobot/core/jpeg.h"
#include "microcobot/devices/camera_frame.h"

namespace mc::live {

inline constexpr int kPreviewMaxWidthPx = 640;  ///< the console's microscope panel (web/index.html)

/// Bins the camera thread's frames for the panel and encodes them; one per camera thread (its
/// buffers are kept from frame to frame).
class CameraPreview {
 public:
  /// The binning factor for an image `width_px` wide: the smallest integer that brings it to at
  /// most `max_width_px` (1: the image is already that small).
  static int binning(int width_px, int max_width_px = kPreviewMaxWidthPx);

  /// Bins `image` by binning(image.width) in both directions (the mean of each f x f block; the
  /// right and bottom remainders that do not fill a block are left out), takes the top 8 bits of
  /// deeper samples as the full frame's JPEG does, and encodes it at `quality`. Returns the JPEG.
  const std::vector<std::uint8_t>& encode(const devices::Image& image, int quality);

  int width() const { return binned_.width; }
  int height() const { return binned_.height; }
  /// The binned 8-bit image of the last encode().
  const devices::Image& binned() const { return binned_; }

 private:
  devices::Image binned_;
  std::vector<std::uint32_t> row_sums_;
  std::vector<std::uint16_t> deep_row_;  // one row of 10-16 bit samples
  std::vector<std::uint8_t> jpeg_;
  JpegEncoder encoder_;
};

}  // namespace mc::live
