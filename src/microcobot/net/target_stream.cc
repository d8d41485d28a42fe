#include "microcobot/net/target_stream.h"

#include <cmath>

namespace mc::net {

TargetStream::TargetStream(const motion::SetpointStreamParams& stream, double window_s)
    : axes_{motion::SetpointStream(stream), motion::SetpointStream(stream), motion::SetpointStream(stream)},
      transit_(window_s) {}

bool TargetStream::push(double stamp_s, const Axes3& target_m, double now_s) noexcept {
  if (!std::isfinite(stamp_s) || !std::isfinite(now_s)) return false;
  const double transit = now_s - stamp_s;
  const double known = transit_.estimate_s();
  if (std::isfinite(known) && transit < known - kMaxStampLead_s) return false;
  bool taken = true;
  for (std::size_t i = 0; i < 3; ++i) taken = axes_[i].push(stamp_s, target_m[i]) && taken;
  if (!taken) return false;
  transit_.observe(transit, now_s);
  return true;
}

TargetStream::Axes3 TargetStream::sample(double now_s, double dt_s) noexcept {
  Axes3 out{};
  // Before the first target the streams hold their start (any read time does).
  const double transit_s = transit_.estimate_s();
  const double sender_now = std::isfinite(transit_s) ? now_s - transit_s : now_s;
  holding_ = false;
  for (std::size_t i = 0; i < 3; ++i) {
    out[i] = axes_[i].sample(sender_now, dt_s).x_m;
    holding_ = holding_ || axes_[i].holding();
  }
  return out;
}

void TargetStream::reset(const Axes3& target_m) noexcept {
  for (std::size_t i = 0; i < 3; ++i) axes_[i].reset(target_m[i]);
  transit_.reset();
  holding_ = true;
}

}  // namespace mc::net
