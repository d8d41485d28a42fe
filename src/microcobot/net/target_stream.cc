#include "microcobot/net/target_stream.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "microcobot/core/error.h"

namespace mc::net {

namespace {
constexpr double kNone = std::numeric_limits<double>::infinity();
}

TargetStream::TargetStream(const control::SetpointStreamParams& stream, double window_s)
    : axes_{control::SetpointStream(stream), control::SetpointStream(stream),
            control::SetpointStream(stream)},
      window_s_(window_s),
      transit_s_(kNone),
      bucket_min_s_(kNone),
      previous_min_s_(kNone) {
  require(std::isfinite(window_s) && window_s >= 0.01 && window_s <= 60.0, "window_s",
          "must be within [0.01, 60] s", window_s);
}

bool TargetStream::push(double stamp_s, const Axes3& target_m, double now_s) noexcept {
  if (!std::isfinite(stamp_s) || !std::isfinite(now_s)) return false;
  const double transit = now_s - stamp_s;
  if (std::isfinite(transit_s_) && transit < transit_s_ - kMaxStampLead_s) return false;
  bool taken = true;
  for (std::size_t i = 0; i < 3; ++i) taken = axes_[i].push(stamp_s, target_m[i]) && taken;
  if (!taken) return false;
  bucket_min_s_ = std::min(bucket_min_s_, transit);
  transit_s_ = std::min(transit_s_, transit);
  return true;
}

TargetStream::Axes3 TargetStream::sample(double now_s, double dt_s) noexcept {
  Axes3 out{};
  if (now_s - bucket_start_s_ >= window_s_) {
    previous_min_s_ = bucket_min_s_;
    bucket_min_s_ = kNone;
    bucket_start_s_ = now_s;
    // Over the two windows; none arrived in either: keep the last estimate.
    if (previous_min_s_ < kNone) transit_s_ = previous_min_s_;
  }
  // Before the first target the streams hold their start (any read time does).
  const double sender_now = std::isfinite(transit_s_) ? now_s - transit_s_ : now_s;
  holding_ = false;
  for (std::size_t i = 0; i < 3; ++i) {
    out[i] = axes_[i].sample(sender_now, dt_s).x_m;
    holding_ = holding_ || axes_[i].holding();
  }
  return out;
}

void TargetStream::reset(const Axes3& target_m) noexcept {
  for (std::size_t i = 0; i < 3; ++i) axes_[i].reset(target_m[i]);
  transit_s_ = bucket_min_s_ = previous_min_s_ = kNone;
  holding_ = true;
}

}  // namespace mc::net
