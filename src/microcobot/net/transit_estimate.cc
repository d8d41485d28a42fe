#include "microcobot/net/transit_estimate.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "microcobot/core/error.h"

namespace mc::net {

namespace {
constexpr double kNone = std::numeric_limits<double>::infinity();
}

TransitEstimate::TransitEstimate(double window_s) : window_s_(window_s) {
  require(std::isfinite(window_s) && window_s >= 0.01 && window_s <= 60.0, "window_s",
          "must be within [0.01, 60] s", window_s);
  reset();
}

void TransitEstimate::reset() noexcept {
  estimate_s_ = bucket_min_s_ = previous_min_s_ = kNone;
  bucket_start_s_ = -kNone;
}

double TransitEstimate::observe(double transit_s, double now_s) noexcept {
  if (!std::isfinite(transit_s) || !std::isfinite(now_s)) return kNone;
  if (!std::isfinite(bucket_start_s_)) bucket_start_s_ = now_s;
  if (now_s - bucket_start_s_ >= window_s_) {
    // Turned by a sample only: after an outage the bucket before it still holds the route.
    previous_min_s_ = bucket_min_s_;
    bucket_min_s_ = kNone;
    bucket_start_s_ = now_s;
    estimate_s_ = previous_min_s_;
  }
  bucket_min_s_ = std::min(bucket_min_s_, transit_s);
  estimate_s_ = std::min(estimate_s_, transit_s);
  return transit_s - estimate_s_;
}

}  // namespace mc::net
