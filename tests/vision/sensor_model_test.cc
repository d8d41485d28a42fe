// The sensor's read-out against the photon-transfer model (EMVA 1288): the mean and variance of
// a flat field, at high counts (Gaussian path) and low counts (exact Poisson path).

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "microcobot/vision/renderer.h"

namespace mc::vision {
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
}  // namespace mc::vision
