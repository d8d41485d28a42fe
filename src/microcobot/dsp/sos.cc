#include "microcobot/dsp/sos.h"

#include <cmath>
#include <string>

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

void SosFilter::process(std::span<const double> in, std::span<double> out) {
  if (out.size() != in.size()) throw InvalidParams("out", "must have the size of the input block");
  const std::size_t n = in.size();
  const double* src = in.data();
  for (std::size_t i = 0; i < sections_.size(); ++i) {
    const Biquad s = sections_[i];
    double z0 = state_[2 * i];
    double z1 = state_[2 * i + 1];
    double* dst = out.data();
    for (std::size_t k = 0; k < n; ++k) {
      const double x = src[k];
      const double y = s.b0 * x + z0;
      z0 = s.b1 * x - s.a1 * y + z1;
      z1 = s.b2 * x - s.a2 * y;
      dst[k] = y;
    }
    state_[2 * i] = z0;
    state_[2 * i + 1] = z1;
    src = out.data();  // next section filters this section's output in place
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
