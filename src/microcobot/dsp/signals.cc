#include "microcobot/dsp/signals.h"

#include <cmath>
#include <numbers>

#include "microcobot/core/error.h"
#include "microcobot/core/rng.h"

namespace mc::dsp {

std::vector<int> mls_taps(int nbits) {
  require(nbits >= 2 && nbits <= 32, "nbits", "must be in [2, 32]", nbits);
  // scipy.signal._max_len_seq._mls_taps (first option of each row of the New Wave
  // Instruments table).
  static const std::vector<int> kTaps[33] = {
      {},          {},        {1},         {2},          {3},         {3},          {5},
      {6},         {7, 6, 1}, {5},         {7},          {9},         {11, 10, 4},  {12, 11, 8},
      {13, 12, 2}, {14},      {15, 13, 4}, {14},         {11},        {18, 17, 14}, {17},
      {19},        {21},      {18},        {23, 22, 17}, {22},        {25, 24, 20}, {26, 25, 22},
      {25},        {27},      {29, 28, 7}, {28},         {31, 30, 10}};
  return kTaps[nbits];
}

std::vector<std::uint8_t> max_len_seq(int nbits, std::size_t length) {
  const auto taps = mls_taps(nbits);
  const std::size_t n = static_cast<std::size_t>(nbits);
  if (length == 0) length = (std::size_t{1} << n) - 1;
  std::vector<std::uint8_t> state(n, 1), seq(length);
  std::vector<std::size_t> tap_offsets(taps.begin(), taps.end());
  // The register is a ring: idx is the oldest bit (scipy's _max_len_seq_inner).
  std::size_t idx = 0;
  for (std::size_t i = 0; i < length; ++i) {
    std::uint8_t feedback = state[idx];
    seq[i] = feedback;
    for (std::size_t t : tap_offsets) {
      std::size_t j = idx + t;
      if (j >= n) j -= n;
      feedback ^= state[j];
    }
    state[idx] = feedback;
    if (++idx == n) idx = 0;
  }
  return seq;
}

std::vector<double> prbs(int nbits, std::size_t length, int clock_divider, double amplitude) {
  require(clock_divider >= 1, "clock_divider", "must be >= 1", clock_divider);
  require_positive(amplitude, "amplitude");
  const std::size_t div = static_cast<std::size_t>(clock_divider);
  const std::size_t bits_needed = (length + div - 1) / div;
  const std::size_t period = (std::size_t{1} << static_cast<std::size_t>(nbits)) - 1;
  const auto seq = max_len_seq(nbits, std::min(bits_needed, period));
  std::vector<double> out(length);
  for (std::size_t k = 0; k < length; ++k) out[k] = seq[(k / div) % seq.size()] ? amplitude : -amplitude;
  return out;
}

std::vector<double> log_sweep(double f0_Hz, double f1_Hz, double duration_s, double fs_Hz, double amplitude) {
  require_positive(fs_Hz, "fs_Hz");
  require(std::isfinite(f0_Hz) && f0_Hz > 0 && f0_Hz <= fs_Hz / 2, "f0_Hz", "must be in (0, fs/2]", f0_Hz);
  require(std::isfinite(f1_Hz) && f1_Hz > 0 && f1_Hz <= fs_Hz / 2, "f1_Hz", "must be in (0, fs/2]", f1_Hz);
  require(f0_Hz != f1_Hz, "f1_Hz", "must differ from f0_Hz", f1_Hz);
  require_positive(duration_s, "duration_s");
  const auto n = static_cast<std::size_t>(std::floor(duration_s * fs_Hz)) + 1;
  const double beta = duration_s / std::log(f1_Hz / f0_Hz);
  std::vector<double> out(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / fs_Hz;
    const double phase =
        2.0 * std::numbers::pi * beta * f0_Hz * (std::pow(f1_Hz / f0_Hz, t / duration_s) - 1.0);
    out[k] = amplitude * std::cos(phase);
  }
  return out;
}

std::vector<double> white_noise(std::size_t n, double stddev, std::uint64_t seed) {
  require_non_negative(stddev, "stddev");
  Rng rng(seed);
  std::vector<double> out(n);
  for (double& v : out) v = stddev * rng.normal();
  return out;
}

double sawtooth_value(double phase_rad, double rise_fraction) {
  const double two_pi = 2.0 * std::numbers::pi;
  double t = std::fmod(phase_rad, two_pi);
  if (t < 0) t += two_pi;
  const double w = rise_fraction;
  if (t < w * two_pi) return t / (std::numbers::pi * w) - 1.0;
  return (std::numbers::pi * (w + 1.0) - t) / (std::numbers::pi * (1.0 - w));
}

std::vector<double> sawtooth(std::size_t n, double f_Hz, double fs_Hz, double amplitude,
                             double rise_fraction) {
  require_positive(fs_Hz, "fs_Hz");
  require_non_negative(f_Hz, "f_Hz");
  require_in_range(rise_fraction, 0.0, 1.0, "rise_fraction");
  std::vector<double> out(n);
  for (std::size_t k = 0; k < n; ++k) {
    out[k] = amplitude *
             sawtooth_value(2.0 * std::numbers::pi * f_Hz * static_cast<double>(k) / fs_Hz, rise_fraction);
  }
  return out;
}

std::vector<double> sine(std::size_t n, double f_Hz, double fs_Hz, double amplitude, double phase_rad) {
  require_positive(fs_Hz, "fs_Hz");
  std::vector<double> out(n);
  for (std::size_t k = 0; k < n; ++k) {
    out[k] = amplitude * std::sin(2.0 * std::numbers::pi * f_Hz * static_cast<double>(k) / fs_Hz + phase_rad);
  }
  return out;
}

std::vector<double> step_signal(std::size_t n, double fs_Hz, double t0_s, double amplitude) {
  require_positive(fs_Hz, "fs_Hz");
  std::vector<double> out(n);
  for (std::size_t k = 0; k < n; ++k) out[k] = static_cast<double>(k) / fs_Hz >= t0_s ? amplitude : 0.0;
  return out;
}

}  // namespace mc::dsp
