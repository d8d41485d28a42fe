#include "microcobot/dsp/sos.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <string>
#include <utility>

#include "microcobot/core/error.h"

namespace mc::dsp {

Biquad Biquad::from_row(const std::array<double, 6>& row) {
  for (double v : row) require(std::isfinite(v), "sos", "coefficients must be finite");
  require(row[3] != 0.0, "sos.a0", "must be non-zero", row[3]);
  const double a0 = row[3];
  return Biquad{row[0] / a0, row[1] / a0, row[2] / a0, row[4] / a0, row[5] / a0};
}

SosFilter::SosFilter(Sos sections) : sections_(std::move(sections)), state_(2 * sections_.size(), 0.0) {
  require(!sections_.empty(), "sos", "must hold at least one section");
  for (const auto& s : sections_) {
    require(std::isfinite(s.b0) && std::isfinite(s.b1) && std::isfinite(s.b2) && std::isfinite(s.a1) &&
                std::isfinite(s.a2),
            "sos", "coefficients must be finite");
  }
}

namespace {

/// One TDF-II update of section `s` with states z0, z1, in scipy's operation order
/// (scipy/signal/_sosfilt.pyx), so that the result is bit-identical to sosfilt.
inline double tdf2(const Biquad& s, double x, double& z0, double& z1) noexcept {
  const double y = s.b0 * x + z0;
  z0 = s.b1 * x - s.a1 * y + z1;
  z1 = s.b2 * x - s.a2 * y;
  return y;
}

/// Runs G consecutive sections over a block as a wavefront: in one pass over the samples,
/// section g works on sample k - g, fed by the output section g - 1 produced in the previous
/// iteration. The G recurrences are independent within an iteration, so their dependency chains
/// (4 dependent floating-point operations per sample, ~16 cycles) overlap instead of adding up;
/// every section still sees the same inputs in the same order with the same operations, so
/// the output is bit-identical to filtering section by section. States and coefficients live in
/// locals (registers or the stack), never behind a pointer the output could alias. `dst` may
/// equal `src`: the write at k - G + 1 never overtakes the read at k.
template <int G>
void run_wavefront(const Biquad* sec, double* state, const double* src, double* dst, std::size_t n) noexcept {
  Biquad s[G];
  double z0[G], z1[G], carry[G];
  for (int g = 0; g < G; ++g) {
    s[g] = sec[g];
    z0[g] = state[2 * g];
    z1[g] = state[2 * g + 1];
    carry[g] = 0.0;
  }
  const std::ptrdiff_t nn = static_cast<std::ptrdiff_t>(n);
  // Ramp-up and ramp-down: only the sections whose sample index k - g is inside the block run.
  auto partial = [&](std::ptrdiff_t k) {
    for (int g = G - 1; g >= 0; --g) {
      const std::ptrdiff_t j = k - g;
      if (j < 0 || j >= nn) continue;
      const double x = g == 0 ? src[j] : carry[g - 1];
      carry[g] = tdf2(s[g], x, z0[g], z1[g]);
      if (g == G - 1) dst[j] = carry[g];
    }
  };
  std::ptrdiff_t k = 0;
  for (; k < G - 1 && k < nn; ++k) partial(k);
  for (; k < nn; ++k) {
    double in[G];
    in[0] = src[k];
    for (int g = 1; g < G; ++g) in[g] = carry[g - 1];
    for (int g = 0; g < G; ++g) carry[g] = tdf2(s[g], in[g], z0[g], z1[g]);
    dst[k - (G - 1)] = carry[G - 1];
  }
  for (; k < nn + G - 1; ++k) partial(k);
  for (int g = 0; g < G; ++g) {
    state[2 * g] = z0[g];
    state[2 * g + 1] = z1[g];
  }
}

/// Sections per wavefront: enough independent recurrences to hide the latency of one.
constexpr std::size_t kGroup = 8;

using WavefrontFn = void (*)(const Biquad*, double*, const double*, double*, std::size_t) noexcept;

template <std::size_t... I>
constexpr std::array<WavefrontFn, sizeof...(I)> wavefront_table(std::index_sequence<I...>) {
  return {&run_wavefront<static_cast<int>(I) + 1>...};
}
/// kWavefront[g - 1] runs a group of g sections.
constexpr auto kWavefront = wavefront_table(std::make_index_sequence<kGroup>{});

}  // namespace

void SosFilter::process(std::span<const double> in, std::span<double> out) {
  if (out.size() != in.size()) throw InvalidParams("out", "must have the size of the input block");
  const std::size_t n = in.size();
  const double* src = in.data();
  double* dst = out.data();
  // Groups of up to kGroup sections run as wavefronts; the next group filters this one's output
  // in place.
  std::size_t i = 0;
  while (i < sections_.size()) {
    const std::size_t g = std::min(kGroup, sections_.size() - i);
    kWavefront[g - 1](&sections_[i], &state_[2 * i], src, dst, n);
    i += g;
    src = dst;
  }
}

void SosFilter::reset() {
  for (double& z : state_) z = 0.0;
}

void SosFilter::reset_to_steady_state(double x) {
  // For a constant input x the section output is y = g x with g = B(1)/A(1); the TDF-II
  // states then are z1 = y - b0 x and z2 = b2 x - a2 y.
  for (std::size_t i = 0; i < sections_.size(); ++i) {
    const Biquad& s = sections_[i];
    const double den = 1.0 + s.a1 + s.a2;
    if (den == 0.0) throw ComputationFailed("sos section " + std::to_string(i) + " has a pole at z = 1");
    const double y = x * (s.b0 + s.b1 + s.b2) / den;
    state_[2 * i] = y - s.b0 * x;
    state_[2 * i + 1] = s.b2 * x - s.a2 * y;
    x = y;
  }
}

std::vector<double> sosfilt(const Sos& sos, std::span<const double> x) {
  SosFilter f(sos);
  std::vector<double> y(x.size());
  f.process(x, y);
  return y;
}

}  // namespace mc::dsp
