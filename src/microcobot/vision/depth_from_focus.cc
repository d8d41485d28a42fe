#include "microcobot/vision/depth_from_focus.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "microcobot/core/error.h"

namespace mc::vision {

double parabola_vertex(double za, double ya, double zb, double yb, double zc, double yc) {
  const double p = (zb - za) * (yb - yc), q = (zb - zc) * (yb - ya);
  const double den = p - q;
  const double num = (zb - za) * p - (zb - zc) * q;
  if (den == 0.0 || !std::isfinite(num / den)) return zb;
  return zb - 0.5 * num / den;
}

namespace {

// Weighted least-squares parabola y = c0 + c1 u + c2 u^2 (u = z - z0) by its 3 x 3 normal
// equations (Cramer's rule); returns false when they are singular or the parabola opens the
// wrong way (no maximum of F).
bool fit_vertex(std::span<const FocusSample> samples, double z0, double lo, double hi, PeakModel model,
                double& vertex, int& count) {
  double s[5] = {0, 0, 0, 0, 0}, t[3] = {0, 0, 0};
  count = 0;
  for (const FocusSample& x : samples) {
    if (x.z_m < lo || x.z_m > hi || x.sharpness <= 0.0) continue;
    const double f = x.sharpness;
    const double y = model == PeakModel::kLorentzian ? 1.0 / f : std::log(f);
    const double w = model == PeakModel::kLorentzian ? f * f * f * f : f * f;
    const double u = x.z_m - z0;
    double p = w;
    for (int k = 0; k < 5; ++k, p *= u) s[k] += p;
    t[0] += w * y, t[1] += w * y * u, t[2] += w * y * u * u;
    ++count;
  }
  if (count < 3) return false;
  const auto det3 = [](double a, double b, double c, double d, double e, double f, double g, double h,
                       double i) { return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g); };
  const double d = det3(s[0], s[1], s[2], s[1], s[2], s[3], s[2], s[3], s[4]);
  if (d == 0.0 || !std::isfinite(d)) return false;
  const double d1 = det3(s[0], t[0], s[2], s[1], t[1], s[3], s[2], t[2], s[4]);
  const double d2 = det3(s[0], s[1], t[0], s[1], s[2], t[1], s[2], s[3], t[2]);
  const double c1 = d1 / d, c2 = d2 / d;
  // A maximum of F: 1/F (or ln F) must be a parabola opening up (down).
  if (model == PeakModel::kLorentzian ? !(c2 > 0.0) : !(c2 < 0.0)) return false;
  vertex = z0 - 0.5 * c1 / c2;
  return std::isfinite(vertex);
}

}  // namespace

FocusPeak focus_peak(std::span<const FocusSample> samples, const FocusPeakParams& params) {
  FocusPeak out;
  if (samples.empty()) {
    out.reason = "no samples";
    return out;
  }
  std::size_t best = 0;
  double lo = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const FocusSample& s = samples[i];
    if (!std::isfinite(s.z_m) || !std::isfinite(s.sharpness) || s.sharpness < 0.0)
      throw InvalidInput("focus sample " + std::to_string(i) + ": height " + std::to_string(s.z_m) +
                         " m, measure " + std::to_string(s.sharpness) +
                         " (expected a finite height and a finite measure >= 0)");
    if (s.sharpness > samples[best].sharpness) best = i;
    lo = std::min(lo, s.sharpness);
  }
  const FocusSample& b = samples[best];
  out.z_m = b.z_m;
  out.sharpness = b.sharpness;
  out.contrast = b.sharpness <= 0.0 ? 1.0
                 : lo > 0.0         ? b.sharpness / lo
                                    : std::numeric_limits<double>::infinity();
  if (out.contrast < params.min_contrast) {
    out.reason = "no peak: the focus measure is flat (a textureless region?)";
    return out;
  }
  // The nearest samples below and above the sharpest one.
  const FocusSample* below = nullptr;
  const FocusSample* above = nullptr;
  for (const FocusSample& s : samples) {
    if (s.z_m < b.z_m && (!below || s.z_m > below->z_m)) below = &s;
    if (s.z_m > b.z_m && (!above || s.z_m < above->z_m)) above = &s;
  }
  if (!below || !above) {
    out.reason = "no peak: the sharpest sample is at the sweep's end";
    return out;
  }
  // The peak region: the contiguous run of samples around the sharpest with F >= fraction x max
  // (found by walking outwards in z), widened to its nearest neighbours at the least.
  const double f_cut = params.peak_fraction * b.sharpness;
  double z_lo = below->z_m, z_hi = above->z_m;
  for (bool up : {false, true}) {
    double edge = b.z_m;
    for (;;) {
      const FocusSample* next = nullptr;  // the nearest sample beyond `edge` on this side
      for (const FocusSample& s : samples)
        if ((up ? s.z_m > edge : s.z_m < edge) && (!next || (up ? s.z_m < next->z_m : s.z_m > next->z_m)))
          next = &s;
      if (!next || next->sharpness < f_cut) break;
      edge = next->z_m;
    }
    if (up)
      z_hi = std::max(z_hi, edge);
    else
      z_lo = std::min(z_lo, edge);
  }
  double z = b.z_m;
  int count = 0;
  if (!fit_vertex(samples, b.z_m, z_lo, z_hi, params.model, z, count)) {
    // The three around the peak always bracket it.
    const auto y = [&](double f) {
      return params.model == PeakModel::kLorentzian ? -1.0 / std::max(f, 1e-300)
                                                    : std::log(std::max(f, 1e-300));
    };
    z = parabola_vertex(below->z_m, y(below->sharpness), b.z_m, y(b.sharpness), above->z_m,
                        y(above->sharpness));
    count = 3;
  }
  // Unimodal: the peak lies between the sharpest sample's neighbours.
  out.z_m = std::clamp(z, below->z_m, above->z_m);
  out.fitted = count;
  out.found = true;
  return out;
}

}  // namespace mc::vision
