#include "microcobot/imaging/sensor_model.h"

#include <algorithm>
#include <cmath>

namespace mc::imaging {

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
  inverse_cdf_[0] = inverse_cdf_[1];  // unused: the outer bins have their own table
  inverse_cdf_[n] = inverse_cdf_[n - 1];
  // The lowest bin, u < 1/4096 (z < -3.4), on a grid of 2^-24; the highest by symmetry.
  tail_cdf_.resize(n + 1);
  for (int i = 1; i <= n; ++i)
    tail_cdf_[i] = static_cast<float>(normal_quantile(static_cast<double>(i) * 0x1.0p-24));
  tail_cdf_[0] = tail_cdf_[1];  // unused: u < 2^-24 is computed exactly
}

// u32 in the lowest bin (u32 < 2^20): the tail table, and below 2^-24 (one draw in 17 million)
// Newton's method. The quantile's curvature there keeps the interpolation within 2e-3 of z.
[[gnu::cold]] double SensorModel::lower_tail_normal(std::uint32_t u32) const noexcept {
  const std::uint32_t sub = u32 >> 8;
  if (sub == 0) return normal_quantile((static_cast<double>(u32) + 0.5) * 0x1.0p-32);
  const double t = static_cast<double>(u32 & 0xFFu) * 0x1.0p-8;
  const double lo = double(tail_cdf_[sub]), hi = double(tail_cdf_[sub + 1]);
  return lo + t * (hi - lo);
}

[[gnu::always_inline]] inline double SensorModel::normal(std::uint32_t u32) const noexcept {
  // Linear interpolation of the quantile between table nodes; the two outer bins (u within
  // 1/4096 of 0 or 1, |z| > 3.4) on their finer table (the upper one as z(u) = -z(1 - u)).
  const std::uint32_t bin = u32 >> (32 - kTableBits);
  if (bin == 0) [[unlikely]]
    return lower_tail_normal(u32);
  if (bin == (1u << kTableBits) - 1) [[unlikely]]
    return -lower_tail_normal(~u32);
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
  // |normal(u)| <= 6.24 for every 32-bit u: a pixel whose shot-noise draw cannot reach the
  // clipped well's lower end needs no second draw (the min below would not take it).
  constexpr double kZMax = 6.5;
  const double read = std::sqrt(read2);
  const double clip_from = full - kZMax * read;
  const float* mean = mean_photo_e.data();
  std::uint16_t* dn = out.pixels.data();
  for (std::size_t i = 0; i < n; ++i) {
    const double mu = static_cast<double>(mean[i]) + dark;
    double e;
    if (!noise) {
      e = std::min(mu, full);
    } else {
      const std::uint64_t r = mix64(key + i * 0x9e3779b97f4a7c15ULL);
      const auto u1 = static_cast<std::uint32_t>(r), u2 = static_cast<std::uint32_t>(r >> 32);
      if (mu >= kExactPoissonBelow) {
        // Shot and read noise together: one normal of variance mu + sigma_r^2 (below the full
        // well; above it the well is clipped and only the read noise remains).
        const double s = std::sqrt(mu + read2);
        e = mu + s * normal(u1);
        if (mu + kZMax * s > clip_from) [[unlikely]]
          e = mu < full ? std::min(e, full + read * normal(u2)) : full + read * normal(u2);
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
        e = count + read * normal(u2);
      }
    }
    // Rounded to the nearest DN and clipped to [0, top]: clipped first to [0, top + 1/2], where
    // truncation is the floor.
    dn[i] = static_cast<std::uint16_t>(std::clamp(k * e + 0.5, 0.0, top + 0.5));
  }
}

}  // namespace mc::imaging
