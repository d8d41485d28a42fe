#pragma once
/// @file
/// The sensor's read-out (EMVA 1288 linear camera model): the expected photo-electrons of each
/// pixel mu_p plus the dark signal mu_d = dark_current t_exp become
///   e  = Poisson(mu_p + mu_d), clipped at the full well,   plus read noise N(0, sigma_r^2),
///   DN = round(K e), clipped to [0, 2^bits - 1],           K = gain (2^bits - 1) / full_well,
/// so that (photon-transfer model) mean DN = K (mu_p + mu_d) and
///   var DN = K^2 (mu_p + mu_d + sigma_r^2) + 1/12 (quantisation), below saturation.
/// Poisson draws are exact (inversion) below kExactPoissonBelow electrons and the Gaussian
/// N(mu, mu) above, where the skewness 1/sqrt(mu) is under 0.18. Random numbers come from a
/// counter-based hash of (seed, frame index, pixel): a frame is the same whatever rendered before.

#include <cstdint>
#include <vector>

#include "microcobot/imaging/camera_params.h"

namespace mc::imaging {

/// A camera frame: width x height digital numbers, row-major, top row first.
struct Frame {
  int width = 0;
  int height = 0;
  int bit_depth = 8;
  std::vector<std::uint16_t> pixels;
  std::uint64_t frame_index = 0;
};

/// Exposure and gain may change frame to frame (the camera's controls).
struct SensorControls {
  double exposure_s = 10e-3;
  double gain = 1.0;
};

class SensorModel {
 public:
  static constexpr double kExactPoissonBelow = 30.0;  ///< electrons

  explicit SensorModel(const SensorParams& params);
  const SensorParams& params() const { return p_; }

  /// Reads out `mean_photo_e` (expected photo-electrons per pixel, without the dark signal) into
  /// `out` (resized on the first call only). `noise` false: the expected values, rounded.
  void read_out(const std::vector<float>& mean_photo_e, const SensorControls& controls, std::uint64_t seed,
                std::uint64_t frame_index, bool noise, Frame& out) const;

 private:
  double normal(std::uint32_t u) const noexcept;
  double lower_tail_normal(std::uint32_t u) const noexcept;

  SensorParams p_;
  std::vector<float> inverse_cdf_;  ///< standard normal quantiles on a uniform grid of u
  std::vector<float> tail_cdf_;     ///< the same on a 4096 times finer grid of the lowest bin
};

}  // namespace mc::imaging
