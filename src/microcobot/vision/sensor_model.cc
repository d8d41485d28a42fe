#include "microcobot/vision/sensor_model.h"

#include <algorithm>
#include <cmath>

namespace mc::vision {

namespace {

constexpr int kTableBits = 12;  // 4096 bins of u for the normal quantiles

std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Standard normal quantile by Newton's method on erfc (table construction and the tails).
double normal_quantile(double u) {
  double z = 0.0;
  for (int i = 0; i < 60; ++i) {
    const double f = 0.5 * std::erfc(-z / std::sqrt(2.0)) - u;
    const double d = std::exp(-0.5 * z * z) / std::sqrt(2.0 * M_PI);
    const double step = f / std::max(d, 1e-300);
    z -= std::clamp(step, -1.0, 1.0);
    if (std::abs(step) < 1e-12) break;
  }
  return z;
}

}  // namespace

SensorModel::SensorModel(const SensorParams& params) : p_(params) {
  p_.validate();
  const int n = 1 << kTableBits;
  inverse_cdf_.resize(n + 1);
  for (int i = 1; i < n; ++i)
    inverse_cdf_[i] = static_cast<float>(normal_quantile(static_cast<double>(i) / n));
  inverse_cdf_[0] = inverse_cdf_[1];  // unused: the outer bins are computed exactly
  inverse_cdf_[n] = inverse_cdf_[n - 1];
}

double SensorModel::normal(std::uint32_t u32) const noexcept {
  // Linear interpolation of the quantile between table nodes; the two outer bins (u within
  // 1/4096 of 0 or 1, |z| > 3.4) exactly.
  const std::uint32_t bin = u32 >> (32 - kTableBits);
  const double u = (static_cast<double>(u32) + 0.5) * 0x1.0p-32;
  if (bin == 0 || bin == (1u << kTableBits) - 1) return normal_quantile(u);
  const double t = static_cast<double>(u32 & ((1u << (32 - kTableBits)) - 1)) * 0x1.0p-20;
  const double lo = double(inverse_cdf_[bin]), hi = double(inverse_cdf_[bin + 1]);
  return lo + t * (hi - lo);
}

void SensorModel::read_out(const std::vector<float>& mean_photo_e, const SensorControls& c,
                           std::uint64_t seed, std::uint64_t frame_index, bool noise, Frame& out) const {
  const std::size_t n = static_cast<std::size_t>(p_.width_px) * p_.height_px;
  out.width = p_.width_px;
  out.height = p_.height_px;
  out.bit_depth = p_.bit_depth;
  out.frame_index = frame_index;
  out.pixels.resize(n);
  const double k = c.gain * p_.max_dn() / p_.full_well_e;
  const double dark = p_.dark_current_e_per_s * c.exposure_s;
  const double full = p_.full_well_e, read2 = p_.read_noise_e * p_.read_noise_e;
  const double top = p_.max_dn();
  const std::uint64_t key =
      mix64(mix64(seed) ^ (frame_index * 0x9e3779b97f4a7c15ULL + 0x632be59bd9b4e019ULL));
  for (std::size_t i = 0; i < n; ++i) {
    const double mu = static_cast<double>(mean_photo_e[i]) + dark;
    double e;
    if (!noise) {
      e = std::min(mu, full);
    } else {
      const std::uint64_t r = mix64(key + i * 0x9e3779b97f4a7c15ULL);
      const auto u1 = static_cast<std::uint32_t>(r), u2 = static_cast<std::uint32_t>(r >> 32);
      if (mu >= kExactPoissonBelow) {
        // Shot and read noise together: one normal of variance mu + sigma_r^2 (below the full
        // well; above it the well is clipped and only the read noise remains).
        if (mu < full) {
          e = std::min(mu + std::sqrt(mu + read2) * normal(u1), full + std::sqrt(read2) * normal(u2));
        } else {
          e = full + std::sqrt(read2) * normal(u2);
        }
      } else {
        // Exact Poisson by inversion of its CDF, then the read noise.
        const double u = (static_cast<double>(u1) + 0.5) * 0x1.0p-32;
        double p = std::exp(-mu), cdf = p;
        int count = 0;
        while (u > cdf && count < 200) {
          ++count;
          p *= mu / count;
          cdf += p;
        }
        e = count + std::sqrt(read2) * normal(u2);
      }
    }
    out.pixels[i] = static_cast<std::uint16_t>(std::clamp(std::floor(k * e + 0.5), 0.0, top));
  }
}

}  // namespace mc::vision
