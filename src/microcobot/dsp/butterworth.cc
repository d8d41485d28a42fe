#include "microcobot/dsp/butterworth.h"

#include <cmath>
#include <numbers>

#include "microcobot/core/error.h"

namespace mc::dsp {

using C = std::complex<double>;

namespace {

void check_order(int order, int max_order, const char* field) {
  require(order >= 1 && order <= max_order, field, "must be in [1, " + std::to_string(max_order) + "]",
          order);
}

// Butterworth analog prototype with unit cut-off (scipy.signal.buttap).
Zpk buttap(int order) {
  Zpk zpk;
  for (int m = -order + 1; m < order; m += 2) {
    const double angle = std::numbers::pi * m / (2.0 * order);
    zpk.p.push_back(-std::exp(C(0.0, angle)));
  }
  zpk.k = 1.0;
  return zpk;
}

// Frequency scaling of a low-pass prototype to low-pass or high-pass at wo (lp2lp_zpk, lp2hp_zpk).
Zpk scale(const Zpk& proto, double wo, FilterType type) {
  Zpk out;
  const int degree = static_cast<int>(proto.p.size()) - static_cast<int>(proto.z.size());
  if (type == FilterType::kLowPass) {
    for (const C& z : proto.z) out.z.push_back(z * wo);
    for (const C& p : proto.p) out.p.push_back(p * wo);
    out.k = proto.k * std::pow(wo, degree);
  } else {
    C num(1, 0), den(1, 0);
    for (const C& z : proto.z) {
      out.z.push_back(wo / z);
      num *= -z;
    }
    for (const C& p : proto.p) {
      out.p.push_back(wo / p);
      den *= -p;
    }
    for (int i = 0; i < degree; ++i) out.z.emplace_back(0.0, 0.0);
    out.k = proto.k * (num / den).real();
  }
  return out;
}

Zpk squared(const Zpk& a) {
  Zpk out = a;
  out.z.insert(out.z.end(), a.z.begin(), a.z.end());
  out.p.insert(out.p.end(), a.p.begin(), a.p.end());
  out.k = a.k * a.k;
  return out;
}

int lr_half_order(int order) {
  require(order >= 2 && order <= 40 && order % 2 == 0, "order", "Linkwitz-Riley order must be even, 2..40",
          order);
  return order / 2;
}

}  // namespace

FilterType parse_filter_type(const std::string& text) {
  if (text == "low" || text == "lowpass") return FilterType::kLowPass;
  if (text == "high" || text == "highpass") return FilterType::kHighPass;
  throw UsageError("filter type must be low or high (got '" + text + "')");
}

Zpk butter_analog(int order, double wc_rad_s, FilterType type) {
  check_order(order, 20, "order");
  require_positive(wc_rad_s, "wc_rad_s");
  return scale(buttap(order), wc_rad_s, type);
}

Zpk butter_zpk(int order, double fc_Hz, double fs_Hz, FilterType type) {
  check_order(order, 20, "order");
  require_positive(fs_Hz, "fs_Hz");
  require(std::isfinite(fc_Hz) && fc_Hz > 0 && fc_Hz < fs_Hz / 2, "fc_Hz", "must be in (0, fs/2)", fc_Hz);
  // scipy's route: normalised Wn = 2 fc / fs, design at fs = 2, prewarp 2 fs tan(pi Wn / fs).
  const double wn = 2.0 * fc_Hz / fs_Hz;
  constexpr double kFs = 2.0;
  const double warped = 2.0 * kFs * std::tan(std::numbers::pi * wn / kFs);
  return bilinear_zpk(scale(buttap(order), warped, type), kFs);
}

Sos butter(int order, double fc_Hz, double fs_Hz, FilterType type) {
  return zpk2sos(butter_zpk(order, fc_Hz, fs_Hz, type));
}

Zpk linkwitz_riley_analog(int order, double wc_rad_s, FilterType type) {
  return squared(butter_analog(lr_half_order(order), wc_rad_s, type));
}

Sos linkwitz_riley(int order, double fc_Hz, double fs_Hz, FilterType type) {
  Sos half = butter(lr_half_order(order), fc_Hz, fs_Hz, type);
  Sos out = half;
  out.insert(out.end(), half.begin(), half.end());
  return out;
}

Crossover linkwitz_riley_crossover(int order, double fc_Hz, double fs_Hz) {
  return {linkwitz_riley(order, fc_Hz, fs_Hz, FilterType::kLowPass),
          linkwitz_riley(order, fc_Hz, fs_Hz, FilterType::kHighPass)};
}

std::complex<double> sos_response(const Sos& sos, double f_Hz, double fs_Hz) {
  const C zi = std::exp(C(0.0, -2.0 * std::numbers::pi * f_Hz / fs_Hz));  // z^-1
  const C zi2 = zi * zi;
  C h(1.0, 0.0);
  for (const auto& s : sos) h *= (s.b0 + s.b1 * zi + s.b2 * zi2) / (1.0 + s.a1 * zi + s.a2 * zi2);
  return h;
}

std::complex<double> zpk_response_analog(const Zpk& zpk, double w_rad_s) {
  const C s(0.0, w_rad_s);
  C h(zpk.k, 0.0);
  for (const C& z : zpk.z) h *= s - z;
  for (const C& p : zpk.p) h /= s - p;
  return h;
}

}  // namespace mc::dsp
