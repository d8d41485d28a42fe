#include "microcobot/imaging/gaussian_blur.h"

#include <algorithm>
#include <cmath>

namespace mc::imaging {

namespace {

constexpr double kBoxAbove = 3.0;  // sigma [px] from which three boxes replace the kernel

double phi(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

// Convolves n samples spaced `step` apart (clamped edges) with the odd kernel k[0..2r].
void convolve_line(float* p, int n, int step, const std::vector<float>& k, std::vector<float>& line) {
  const int r = static_cast<int>(k.size() / 2);
  line.resize(static_cast<std::size_t>(n + 2 * r));
  for (int i = 0; i < n + 2 * r; ++i) line[i] = p[std::clamp(i - r, 0, n - 1) * step];
  for (int i = 0; i < n; ++i) {
    float acc = 0.0f;
    const float* src = &line[i];
    for (int j = 0; j <= 2 * r; ++j) acc += k[j] * src[j];
    p[i * step] = acc;
  }
}

// Running-sum box of odd width w over n samples (clamped edges).
void box_line(float* p, int n, int step, int w, std::vector<float>& line) {
  const int r = w / 2;
  line.resize(static_cast<std::size_t>(n + 2 * r + 1));
  for (int i = 0; i < n + 2 * r; ++i) line[i] = p[std::clamp(i - r, 0, n - 1) * step];
  double acc = 0.0;
  for (int j = 0; j < w; ++j) acc += static_cast<double>(line[j]);
  const double inv = 1.0 / w;
  for (int i = 0; i < n; ++i) {
    p[i * step] = static_cast<float>(acc * inv);
    acc += static_cast<double>(line[i + w] - line[i]);
  }
}

// Kovesi's widths: n boxes of odd widths wl or wl + 2 whose variances (w^2 - 1)/12 sum to sigma^2.
void box_widths(double sigma, int (&w)[3]) {
  const int n = 3;
  const double ideal = std::sqrt(12.0 * sigma * sigma / n + 1.0);
  int wl = static_cast<int>(std::floor(ideal));
  if (wl % 2 == 0) --wl;
  const int wu = wl + 2;
  const double m = (12.0 * sigma * sigma - n * wl * wl - 4.0 * n * wl - 3.0 * n) / (-4.0 * wl - 4.0);
  const int mi = static_cast<int>(std::lround(m));
  for (int i = 0; i < n; ++i) w[i] = i < mi ? wl : wu;
}

// The vertical passes run row by row (cache-friendly): a copy of the region is the source.
void copy_region(const float* data, int width, int height, int stride, std::vector<float>& image) {
  image.resize(static_cast<std::size_t>(width) * height);
  for (int y = 0; y < height; ++y)
    std::copy_n(data + static_cast<std::ptrdiff_t>(y) * stride, width,
                image.begin() + static_cast<std::ptrdiff_t>(y) * width);
}

void convolve_columns(float* data, int width, int height, int stride, BlurScratch& s) {
  copy_region(data, width, height, stride, s.image);
  const int r = static_cast<int>(s.kernel.size() / 2);
  for (int y = 0; y < height; ++y) {
    float* out = data + static_cast<std::ptrdiff_t>(y) * stride;
    std::fill_n(out, width, 0.0f);
    for (int j = -r; j <= r; ++j) {
      const float k = s.kernel[j + r];
      const float* src =
          s.image.data() + static_cast<std::ptrdiff_t>(std::clamp(y + j, 0, height - 1)) * width;
      for (int x = 0; x < width; ++x) out[x] += k * src[x];
    }
  }
}

void box_columns(float* data, int width, int height, int stride, int w, BlurScratch& s) {
  copy_region(data, width, height, stride, s.image);
  const int r = w / 2;
  const auto row = [&](int y) {
    return s.image.data() + static_cast<std::ptrdiff_t>(std::clamp(y, 0, height - 1)) * width;
  };
  s.acc.assign(static_cast<std::size_t>(width), 0.0);
  for (int j = -r; j <= r; ++j) {
    const float* src = row(j);
    for (int x = 0; x < width; ++x) s.acc[x] += static_cast<double>(src[x]);
  }
  const double inv = 1.0 / w;
  for (int y = 0; y < height; ++y) {
    float* out = data + static_cast<std::ptrdiff_t>(y) * stride;
    const float* add = row(y + r + 1);
    const float* sub = row(y - r);
    for (int x = 0; x < width; ++x) {
      out[x] = static_cast<float>(s.acc[x] * inv);
      s.acc[x] += static_cast<double>(add[x] - sub[x]);
    }
  }
}

}  // namespace

void gaussian_blur(float* data, int width, int height, int stride, double sigma_px, BlurScratch& s) {
  if (sigma_px <= 1e-3 || width <= 0 || height <= 0) return;
  if (sigma_px < kBoxAbove) {
    const int r = static_cast<int>(std::ceil(4.0 * sigma_px)) + 1;
    s.kernel.resize(static_cast<std::size_t>(2 * r + 1));
    double sum = 0.0;
    for (int j = -r; j <= r; ++j) {
      s.kernel[j + r] = static_cast<float>(phi((j + 0.5) / sigma_px) - phi((j - 0.5) / sigma_px));
      sum += static_cast<double>(s.kernel[j + r]);
    }
    for (float& k : s.kernel) k = static_cast<float>(static_cast<double>(k) / sum);
    for (int y = 0; y < height; ++y)
      convolve_line(data + static_cast<std::ptrdiff_t>(y) * stride, width, 1, s.kernel, s.line);
    convolve_columns(data, width, height, stride, s);
    return;
  }
  int w[3];
  box_widths(sigma_px, w);
  for (int y = 0; y < height; ++y) {
    float* row = data + static_cast<std::ptrdiff_t>(y) * stride;
    for (int b : w) box_line(row, width, 1, b, s.line);
  }
  for (int b : w) box_columns(data, width, height, stride, b, s);
}

}  // namespace mc::imaging
