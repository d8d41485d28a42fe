#include "microcobot/stickslip/drive.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "microcobot/core/error.h"

namespace mc::stickslip {

void DriveParams::validate() const {
  require_positive(slew_rate_V_s, "drive.slew_rate_V_s");
  require(std::isfinite(min_V) && std::isfinite(max_V) && min_V < max_V, "drive.max_V",
          "must be > drive.min_V", max_V);
}

void Waveform::validate(const DriveParams& limits) const {
  require(std::isfinite(amplitude_V) && amplitude_V >= 0.0, "amplitude_V", "must be >= 0", amplitude_V);
  require_positive(slew_rate_V_s, "slew_rate_V_s");
  require(std::isfinite(offset_V) && offset_V >= limits.min_V, "offset_V",
          "drive voltage must stay >= " + std::to_string(limits.min_V) + " V", offset_V);
  require(offset_V + amplitude_V <= limits.max_V + 1e-12, "amplitude_V",
          "offset + amplitude must stay <= " + std::to_string(limits.max_V) + " V (amplifier range)",
          offset_V + amplitude_V);
  if (kind != WaveKind::kStep) {
    require_positive(frequency_Hz, "frequency_Hz");
    if (kind == WaveKind::kSawtooth) {
      // Name the quantity that is out of scale: an absurd slew rate, else the frequency.
      const bool slow_slew = edge_time_s() >= 0.5 && slew_rate_V_s < 1e3;
      require(edge_time_s() < 0.5 / frequency_Hz, slow_slew ? "drive.slew_rate_V_s" : "frequency_Hz",
              fmt::format("the slew-limited edge (amplitude / slew rate = {:g} s) must last less than half "
                          "a period ({:g} s)",
                          edge_time_s(), 0.5 / frequency_Hz),
              slow_slew ? slew_rate_V_s : frequency_Hz);
    }
  }
}

double Waveform::value(double t) const noexcept {
  if (t <= 0.0 || amplitude_V == 0.0) return offset_V;
  const double a = amplitude_V;
  switch (kind) {
    case WaveKind::kStep:
      return offset_V + std::min(a, slew_rate_V_s * t);
    case WaveKind::kSine:
      return offset_V + 0.5 * a * (1.0 - std::cos(2.0 * M_PI * frequency_Hz * t));
    case WaveKind::kSawtooth: {
      const double period = 1.0 / frequency_Hz;
      const double tau = t - period * std::floor(t / period);
      const double edge = edge_time_s();
      const double slow = period - edge;
      if (direction == Direction::kForward) {
        // Slow rise 0 -> A, then the slew-limited drop A -> 0 (Fig. 2.3, forward).
        return offset_V + (tau < slow ? a * tau / slow : a * (period - tau) / edge);
      }
      // Slew-limited rise 0 -> A, then the slow drop A -> 0 (backward).
      return offset_V + (tau < edge ? a * tau / edge : a * (period - tau) / slow);
    }
  }
  return offset_V;
}

DriveSegment Waveform::segment(double t0, double h) const noexcept {
  const double t1 = t0 + h;
  DriveSegment seg;
  seg.end_V = value(t1);
  auto corner = [&](double tc) {
    if (tc > t0 && tc < t1) seg.add_corner((tc - t0) / h, value(tc));
  };
  if (amplitude_V == 0.0 || t1 <= 0.0) return seg;
  switch (kind) {
    case WaveKind::kStep:
      corner(0.0);
      corner(edge_time_s());
      break;
    case WaveKind::kSine: {
      // Extrema of 1 - cos(2 pi f t) at t = n / 2f (n = 0: the start).
      const double half = 0.5 / frequency_Hz;
      for (double n = std::max(0.0, std::ceil(t0 / half)); n * half < t1; n += 1.0) corner(n * half);
      break;
    }
    case WaveKind::kSawtooth: {
      // Each period: its start (U at the offset) and the top of the ramp (U = offset + A), which
      // the forward drive reaches after the slow ramp and the backward one after the edge.
      const double period = 1.0 / frequency_Hz;
      const double top = direction == Direction::kForward ? period - edge_time_s() : edge_time_s();
      for (double k = std::max(0.0, std::floor(t0 / period)); k * period < t1; k += 1.0) {
        corner(k * period);
        corner(k * period + top);
      }
      break;
    }
  }
  return seg;
}

Waveform make_waveform(WaveKind kind, double amplitude_V, double frequency_Hz, Direction direction,
                       const DriveParams& limits, double offset_V) {
  Waveform w;
  w.kind = kind;
  w.amplitude_V = amplitude_V;
  w.frequency_Hz = frequency_Hz;
  w.direction = direction;
  w.offset_V = offset_V;
  w.slew_rate_V_s = limits.slew_rate_V_s;
  w.validate(limits);
  return w;
}

WaveKind parse_wave_kind(const std::string& name) {
  if (name == "sawtooth") return WaveKind::kSawtooth;
  if (name == "sine") return WaveKind::kSine;
  if (name == "step") return WaveKind::kStep;
  throw UsageError("--wave must be sawtooth, sine or step (got '" + name + "')");
}

Direction parse_direction(const std::string& name) {
  if (name == "forward") return Direction::kForward;
  if (name == "backward") return Direction::kBackward;
  throw UsageError("--direction must be forward or backward (got '" + name + "')");
}

std::string to_string(Direction d) { return d == Direction::kForward ? "forward" : "backward"; }
std::string to_string(WaveKind k) {
  switch (k) {
    case WaveKind::kSawtooth:
      return "sawtooth";
    case WaveKind::kSine:
      return "sine";
    case WaveKind::kStep:
      return "step";
  }
  return "sawtooth";
}

}  // namespace mc::stickslip
