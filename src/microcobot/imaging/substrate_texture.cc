#include "microcobot/imaging/substrate_texture.h"

#include <cmath>
#include <cstdint>

namespace mc::imaging {

namespace {

std::uint64_t texture_mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Lattice value in [-1, 1) (variance 1/3).
double lattice(std::uint64_t seed, std::int64_t ix, std::int64_t iy) {
  const std::uint64_t h =
      texture_mix64(seed ^ texture_mix64(static_cast<std::uint64_t>(ix) * 0x9e3779b97f4a7c15ULL +
                                         static_cast<std::uint64_t>(iy) * 0xc2b2ae3d27d4eb4fULL));
  return static_cast<double>(h >> 11) * 0x1.0p-52 - 1.0;
}

double smooth(double t) { return t * t * (3.0 - 2.0 * t); }

}  // namespace

double substrate_texture(const Substrate& s, double x_m, double y_m, double pixel_m) noexcept {
  if (s.texture_contrast <= 0.0 || s.texture_octaves <= 0) return 0.0;
  double sum = 0.0, norm2 = 0.0, amplitude = 1.0, grain = s.texture_grain_m;
  for (int o = 0; o < s.texture_octaves; ++o, amplitude *= 1.4, grain *= 2.0) {
    const std::uint64_t seed =
        texture_mix64(s.texture_seed * 0x100000001b3ULL + static_cast<std::uint64_t>(o));
    norm2 += amplitude * amplitude;
    if (grain < pixel_m) {
      // The pixel averages (pixel/grain)^2 cells: one value per pixel, rms scaled by grain/pixel.
      const auto ix = static_cast<std::int64_t>(std::floor(x_m / pixel_m));
      const auto iy = static_cast<std::int64_t>(std::floor(y_m / pixel_m));
      sum += amplitude * (grain / pixel_m) * lattice(seed, ix, iy);
      continue;
    }
    const double gx = x_m / grain, gy = y_m / grain;
    const double fx = std::floor(gx), fy = std::floor(gy);
    const auto ix = static_cast<std::int64_t>(fx), iy = static_cast<std::int64_t>(fy);
    const double tx = smooth(gx - fx), ty = smooth(gy - fy);
    const double a = lattice(seed, ix, iy), b = lattice(seed, ix + 1, iy);
    const double c = lattice(seed, ix, iy + 1), d = lattice(seed, ix + 1, iy + 1);
    sum += amplitude * ((a + (b - a) * tx) * (1.0 - ty) + (c + (d - c) * tx) * ty);
  }
  // Lattice values have rms 1/sqrt(3): scaled so that the octaves together have rms ~contrast.
  return s.texture_contrast * sum * std::sqrt(3.0) / std::sqrt(norm2);
}

}  // namespace mc::imaging
