#pragma once
/// @file
/// Separable Gaussian blur of a float image region, in place, edges clamped (replicated).
/// Small sigma (< 3 px): the Gaussian integrated over each pixel, k_n = Phi((n+1/2)/sigma) -
/// Phi((n-1/2)/sigma) (exact for a PSF sampled by square pixels; the identity as sigma -> 0).
/// Larger sigma: three box filters whose variances add up to sigma^2 (Wells, IEEE PAMI 8(2),
/// 1986; widths as Kovesi, DICTA 2010), O(1) per pixel whatever sigma.

#include <vector>

namespace mc::imaging {

/// Reusable scratch space, so that a renderer blurs frame after frame without allocating.
struct BlurScratch {
  std::vector<float> line;
  std::vector<float> kernel;
  std::vector<float> image;  ///< a copy of the region for the vertical passes
  std::vector<double> acc;   ///< per-column running sums
};

/// Blurs the `width` x `height` image at `data` (row stride `stride`) by `sigma_px`.
void gaussian_blur(float* data, int width, int height, int stride, double sigma_px, BlurScratch& scratch);

}  // namespace mc::imaging
