#include "microcobot/vision/sharpness.h"

#include <cmath>
#include <cstdint>
#include <string>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"

namespace mc::vision {

namespace {

const struct {
  FocusMetric metric;
  const char* name;
} kNames[] = {{FocusMetric::kNormalizedVariance, "normalized-variance"},
              {FocusMetric::kTenengrad, "tenengrad"},
              {FocusMetric::kBrenner, "brenner"}};

std::string roi_text(const imaging::PixelRoi& r) {
  return "ROI x=" + std::to_string(r.x) + " y=" + std::to_string(r.y) + " width=" + std::to_string(r.width) +
         " height=" + std::to_string(r.height);
}

}  // namespace

const char* focus_metric_name(FocusMetric metric) {
  for (const auto& n : kNames)
    if (n.metric == metric) return n.name;
  return "unknown";
}

FocusMetric parse_focus_metric(const std::string& name) {
  std::string known;
  for (const auto& n : kNames) {
    if (name == n.name) return n.metric;
    known += (known.empty() ? "" : ", ") + std::string(n.name);
  }
  throw InvalidInput("focus metric '" + excerpt(name) + "' is not one of " + known);
}

void validate_roi(const imaging::PixelRoi& roi, int width, int height, int min_side) {
  const std::string image = " of the " + std::to_string(width) + " x " + std::to_string(height) + " image";
  if (roi.width <= 0 || roi.height <= 0)
    throw InvalidInput(roi_text(roi) + " is empty (width and height must be > 0)");
  if (roi.x < 0 || roi.y < 0 || roi.x > width - roi.width || roi.y > height - roi.height)
    throw InvalidInput(roi_text(roi) + " is not inside the frame" + image);
  if (roi.width < min_side || roi.height < min_side)
    throw InvalidInput(roi_text(roi) + " is too small: this focus measure needs " + std::to_string(min_side) +
                       " x " + std::to_string(min_side) + " pixels or more");
}

namespace {

void validate_frame(const imaging::Frame& frame) {
  if (frame.width <= 0 || frame.height <= 0 ||
      frame.pixels.size() != static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height))
    throw InvalidInput("frame of " + std::to_string(frame.width) + " x " + std::to_string(frame.height) +
                       " pixels holds " + std::to_string(frame.pixels.size()) + " values");
}

const std::uint16_t* row(const imaging::Frame& f, int i) {
  return f.pixels.data() + static_cast<std::size_t>(i) * static_cast<std::size_t>(f.width);
}

}  // namespace

double normalized_variance(const imaging::Frame& frame, const imaging::PixelRoi& roi) {
  validate_frame(frame);
  validate_roi(roi, frame.width, frame.height);
  // Integer sums are exact (16-bit values, < 2^32 pixels); the variance from the two-pass form.
  std::uint64_t sum = 0;
  for (int i = roi.y; i < roi.y + roi.height; ++i) {
    const std::uint16_t* p = row(frame, i) + roi.x;
    std::uint64_t s = 0;
    for (int j = 0; j < roi.width; ++j) s += p[j];
    sum += s;
  }
  const double n = static_cast<double>(roi.width) * roi.height;
  const double mean = static_cast<double>(sum) / n;
  if (mean <= 0.0) return 0.0;
  double ss = 0.0;
  for (int i = roi.y; i < roi.y + roi.height; ++i) {
    const std::uint16_t* p = row(frame, i) + roi.x;
    double s = 0.0;
    for (int j = 0; j < roi.width; ++j) {
      const double d = p[j] - mean;
      s += d * d;
    }
    ss += s;
  }
  return ss / (n * mean);
}

double tenengrad(const imaging::Frame& frame, const imaging::PixelRoi& roi, double threshold) {
  validate_frame(frame);
  validate_roi(roi, frame.width, frame.height, 3);
  double sum = 0.0;
  for (int i = roi.y + 1; i < roi.y + roi.height - 1; ++i) {
    const std::uint16_t* up = row(frame, i - 1);
    const std::uint16_t* mid = row(frame, i);
    const std::uint16_t* down = row(frame, i + 1);
    for (int j = roi.x + 1; j < roi.x + roi.width - 1; ++j) {
      // Sobel: Gx = [-1 0 1; -2 0 2; -1 0 1], Gy its transpose (rows down). Integers: exact.
      const int gx = (up[j + 1] + 2 * mid[j + 1] + down[j + 1]) - (up[j - 1] + 2 * mid[j - 1] + down[j - 1]);
      const int gy = (down[j - 1] + 2 * down[j] + down[j + 1]) - (up[j - 1] + 2 * up[j] + up[j + 1]);
      const double g2 = static_cast<double>(gx) * gx + static_cast<double>(gy) * gy;
      if (g2 > threshold) sum += g2;
    }
  }
  return sum / (static_cast<double>(roi.width - 2) * (roi.height - 2));
}

double brenner(const imaging::Frame& frame, const imaging::PixelRoi& roi) {
  validate_frame(frame);
  validate_roi(roi, frame.width, frame.height, 3);
  double sum = 0.0;
  for (int i = roi.y; i < roi.y + roi.height; ++i) {
    const std::uint16_t* p = row(frame, i);
    std::uint64_t s = 0;
    for (int j = roi.x; j < roi.x + roi.width - 2; ++j) {
      const std::int64_t d = static_cast<std::int64_t>(p[j + 2]) - p[j];
      s += static_cast<std::uint64_t>(d * d);
    }
    sum += static_cast<double>(s);
  }
  return sum / (static_cast<double>(roi.width - 2) * roi.height);
}

void SharpnessParams::validate() const {
  bool known = false;
  for (const auto& n : kNames) known = known || metric == n.name;
  require(known, "metric",
          "must be normalized-variance, tenengrad or brenner, not '" + excerpt(metric) + "'");
  require(tenengrad_threshold >= 0.0 && std::isfinite(tenengrad_threshold), "tenengrad_threshold",
          "must be finite and >= 0", tenengrad_threshold);
}

double sharpness(const imaging::Frame& frame, const imaging::PixelRoi& roi, FocusMetric metric,
                 double tenengrad_threshold) {
  switch (metric) {
    case FocusMetric::kTenengrad:
      return tenengrad(frame, roi, tenengrad_threshold);
    case FocusMetric::kBrenner:
      return brenner(frame, roi);
    case FocusMetric::kNormalizedVariance:
      break;
  }
  return normalized_variance(frame, roi);
}

}  // namespace mc::vision
