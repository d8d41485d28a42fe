// The sensor's read-out against the photon-transfer model (EMVA 1288): the mean and variance of
// a flat field, at high counts (Gaussian path) and low counts (exact Poisson path).

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "microcobot/imaging/renderer.h"

namespace mc::imaging {
namespace {

struct Stats {
  double mean, var;
};

Stats frame_stats(const Frame& f) {
  double s = 0, s2 = 0;
  for (std::uint16_t v : f.pixels) s += v, s2 += double(v) * v;
  const double n = static_cast<double>(f.pixels.size());
  return {s / n, s2 / n - (s / n) * (s / n)};
}

void check_flat_field(CameraParams cam, double reflectance) {
  Renderer r(cam);
  SceneSnapshot s;
  s.substrate.reflectance = reflectance;
  s.substrate.texture_contrast = 0.0;
  Frame f;
  r.render(s, r.default_controls(), 11, 0, f);
  const SensorParams& p = cam.sensor;
  const double mu =
      reflectance * cam.illumination.electrons_per_s * p.exposure_s + p.dark_current_e_per_s * p.exposure_s;
  const double k = p.system_gain_dn_per_e();
  const double mean = k * mu, var = k * k * (mu + p.read_noise_e * p.read_noise_e) + 1.0 / 12.0;
  const Stats st = frame_stats(f);
  std::printf("flat field mu %.1f e-, %d-bit: mean %.3f DN (model %.3f), var %.3f DN^2 (model %.3f)\n", mu,
              p.bit_depth, st.mean, mean, st.var, var);
  EXPECT_NEAR(st.mean / mean, 1.0, 0.03) << "mu " << mu << " e-";
  EXPECT_NEAR(st.var / var, 1.0, 0.03) << "mu " << mu << " e-";
}

TEST(SensorModel, FlatFieldMeanAndVarianceFollowThePhotonTransferModel) {
  CameraParams cam;
  check_flat_field(cam, 0.45);  // 3600 e-: the Gaussian path
  cam.sensor.bit_depth = 16;
  check_flat_field(cam, 0.8);
}

TEST(SensorModel, FlatFieldAtLowCountsUsesExactPoisson) {
  CameraParams cam;
  cam.sensor.width_px = 640, cam.sensor.height_px = 512;
  cam.sensor.read_noise_e = 1.0;  // no clipping at 0 DN: the model holds without a black level
  cam.sensor.gain = 20.0;
  cam.sensor.exposure_s = 5e-5;  // 0.45 x 8e5 x 5e-5 = 18 e-: below kExactPoissonBelow
  check_flat_field(cam, 0.45);
}

// The normal draws' tails (|z| > 3.4, their own finer quantile table): the share of a flat
// field's pixels beyond 3.5 and 4 standard deviations against the normal's, within 4 sigma of
// the binomial count.
TEST(SensorModel, TheNoiseHasTheNormalsTails) {
  CameraParams cam;
  cam.sensor.bit_depth = 16;  // fine steps: the quantisation adds 1/12 DN^2 only
  Renderer r(cam);
  SceneSnapshot s;
  s.substrate.reflectance = 0.8;
  s.substrate.texture_contrast = 0.0;
  Frame f;
  r.render(s, r.default_controls(), 5, 3, f);
  const SensorParams& p = cam.sensor;
  const double mu =
      0.8 * cam.illumination.electrons_per_s * p.exposure_s + p.dark_current_e_per_s * p.exposure_s;
  const double k = p.system_gain_dn_per_e();
  const double mean = k * mu, sd = std::sqrt(k * k * (mu + p.read_noise_e * p.read_noise_e) + 1.0 / 12.0);
  const double n = static_cast<double>(f.pixels.size());
  for (double z : {3.5, 4.0}) {
    double below = 0, above = 0;
    for (std::uint16_t v : f.pixels) {
      below += (v - mean) / sd < -z;
      above += (v - mean) / sd > z;
    }
    const double expected = n * 0.5 * std::erfc(z / std::sqrt(2.0));
    std::printf("beyond %.1f sd: %.0f below, %.0f above, %.1f expected each\n", z, below, above, expected);
    EXPECT_NEAR(below, expected, 4.0 * std::sqrt(expected)) << z;
    EXPECT_NEAR(above, expected, 4.0 * std::sqrt(expected)) << z;
  }
}

// Past the full well a pixel holds the well and only the read noise is left; at gain 1 the
// well is the converter's top, so half the pixels read the top and the mean falls short of it by
// the half-normal's K sigma_r / sqrt(2 pi).
TEST(SensorModel, ASaturatedPixelHoldsTheFullWellWithTheReadNoise) {
  CameraParams cam;
  cam.sensor.bit_depth = 16;
  cam.sensor.read_noise_e = 20.0;
  Renderer r(cam);
  SceneSnapshot s;
  s.substrate.reflectance = 1.0;
  s.substrate.texture_contrast = 0.0;
  CameraControls c = r.default_controls();
  const SensorParams& p = cam.sensor;
  c.exposure_s = 3.0 * p.full_well_e / cam.illumination.electrons_per_s;  // three wells' worth
  Frame f;
  r.render(s, c, 9, 0, f);
  const double k = p.system_gain_dn_per_e(), top = p.max_dn();
  double at_top = 0;
  for (std::uint16_t v : f.pixels) {
    at_top += v == top;
    ASSERT_GE(v, top - 7.0 * k * p.read_noise_e);
  }
  const Stats st = frame_stats(f);
  const double deficit = k * p.read_noise_e / std::sqrt(2.0 * M_PI);
  std::printf("saturated: %.4f of the pixels at the top, mean %.1f DN short of it (half-normal %.1f)\n",
              at_top / static_cast<double>(f.pixels.size()), top - st.mean, deficit);
  EXPECT_NEAR(at_top / static_cast<double>(f.pixels.size()), 0.5, 0.01);
  EXPECT_NEAR((top - st.mean) / deficit, 1.0, 0.03);
}

TEST(SensorModel, InvalidParametersNameTheField) {
  CameraParams cam;
  cam.sensor.bit_depth = 20;
  try {
    Renderer r(cam);
    FAIL() << "accepted bit_depth 20";
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("bit_depth"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mc::imaging
