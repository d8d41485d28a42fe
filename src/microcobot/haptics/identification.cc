#include "microcobot/haptics/identification.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Dense>

#include "microcobot/core/error.h"
#include "microcobot/core/rng.h"
#include "microcobot/dsp/signals.h"
#include "microcobot/dsp/welch.h"

namespace mc::haptics {

std::vector<double> table_3_4_centres_Hz() {
  return {63, 80, 100, 125, 160, 200, 250, 315, 400, 500, 630, 800, 1000, 1250};
}

ChannelFrf measure_frf(const DualStagePlant& plant, Channel channel, double amplitude,
                       const IdentificationOptions& o) {
  const std::size_t n = (std::size_t{1} << o.prbs_bits) - 1;
  const std::vector<double> u = dsp::prbs(o.prbs_bits, n, 1, amplitude);
  std::vector<double> y(n);
  DualStagePlantState s;
  Rng rng(o.seed + (channel == Channel::kPantograph ? 0 : 1));
  for (std::size_t k = 0; k < n; ++k) {
    const bool lf = channel == Channel::kPantograph;
    plant.step(s, lf ? u[k] : 0.0, lf ? 0.0 : u[k]);
    y[k] = s.accel_m_s2 + o.noise_m_s2 * rng.normal();
  }
  dsp::WelchOptions w;
  w.fs_Hz = 1.0 / plant.params().dt_s;
  w.nperseg = o.nperseg;
  const dsp::FrfEstimate e = dsp::frf_h1(u, y, w);
  ChannelFrf out;
  out.f_Hz = e.f_Hz;
  out.h = e.h;
  out.coherence = e.coherence;
  return out;
}

HfModel fit_second_order(const ChannelFrf& frf, double lo, double hi, double hold_s) {
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < frf.f_Hz.size(); ++i)
    if (frf.f_Hz[i] >= lo && frf.f_Hz[i] <= hi) idx.push_back(i);
  if (idx.size() < 8) throw ComputationFailed("HF fit: fewer than 8 FRF bins in the fit band");
  // Unknowns theta = [b1, b0, a1, a0]: b1 s + b0 - H (a1 s + a0) = H s^2, weighted by
  // 1/|D_prev(s)| (Sanathanan-Koerner) and 1/|H| (relative error).
  const double f0 = std::sqrt(lo * hi);
  Eigen::Vector4d theta(0, 0, 0, 0);
  double a1 = 0.0, a0 = 0.0;
  bool have_prev = false;
  for (int it = 0; it < 8; ++it) {
    Eigen::MatrixXd a(2 * idx.size(), 4);
    Eigen::VectorXd b(2 * idx.size());
    for (std::size_t r = 0; r < idx.size(); ++r) {
      const std::size_t i = idx[r];
      // Normalised frequency s / w0 keeps the columns at the same scale.
      const std::complex<double> s(0.0, frf.f_Hz[i] / f0);
      // Remove the known half-sample delay of the zero-order hold before fitting a
      // rational model (it would otherwise be absorbed as a right-half-plane zero).
      const std::complex<double> h =
          frf.h[i] * std::exp(std::complex<double>(0.0, -std::numbers::pi * frf.f_Hz[i] * hold_s));
      double wgt = 1.0 / std::max(std::abs(h), 1e-12);
      wgt /= have_prev ? std::abs(s * s + a1 * s + a0) : std::abs(s * s);
      const std::complex<double> c[4] = {s, 1.0, -h * s, -h};
      const std::complex<double> rhs = h * s * s;
      for (int j = 0; j < 4; ++j) {
        a(static_cast<Eigen::Index>(2 * r), j) = wgt * c[j].real();
        a(static_cast<Eigen::Index>(2 * r + 1), j) = wgt * c[j].imag();
      }
      b(static_cast<Eigen::Index>(2 * r)) = wgt * rhs.real();
      b(static_cast<Eigen::Index>(2 * r + 1)) = wgt * rhs.imag();
    }
    theta = a.colPivHouseholderQr().solve(b);
    a1 = theta(2);
    a0 = theta(3);
    have_prev = true;
  }
  const double w0 = 2.0 * std::numbers::pi * f0;
  HfModel m{theta(0) * w0, theta(1) * w0 * w0, theta(2) * w0, theta(3) * w0 * w0};
  // The linear fit matches the complex response, phase included; the channel's phase in the
  // band also carries the magnet's suspension mode, which a 2nd-order low-pass cannot hold.
  // As the thesis (PSD-based, Fig. 3.11) the model is refined on the log-magnitude only
  // (Levenberg-Marquardt on log-parameters, which keeps them positive).
  Eigen::Vector4d p(std::log(std::abs(m.b1) + 1e-9), std::log(std::abs(m.b0) + 1e-9),
                    std::log(std::abs(m.a1) + 1e-9), std::log(std::abs(m.a0) + 1e-9));
  const auto residuals = [&](const Eigen::Vector4d& q) {
    const HfModel mm{std::exp(q(0)), std::exp(q(1)), std::exp(q(2)), std::exp(q(3))};
    Eigen::VectorXd r(static_cast<Eigen::Index>(idx.size()));
    for (std::size_t k = 0; k < idx.size(); ++k) {
      const std::size_t i = idx[k];
      r(static_cast<Eigen::Index>(k)) = 20.0 * std::log10(std::abs(mm.response(frf.f_Hz[i]))) -
                                        20.0 * std::log10(std::max(std::abs(frf.h[i]), 1e-300));
    }
    return r;
  };
  double lambda = 1e-3;
  Eigen::VectorXd r = residuals(p);
  for (int it = 0; it < 100; ++it) {
    Eigen::MatrixXd jac(r.size(), 4);
    for (int j = 0; j < 4; ++j) {
      Eigen::Vector4d q = p;
      q(j) += 1e-6;
      jac.col(j) = (residuals(q) - r) / 1e-6;
    }
    const Eigen::Matrix4d jtj = jac.transpose() * jac;
    const Eigen::Vector4d g = jac.transpose() * r;
    const Eigen::Matrix4d aug = jtj + lambda * Eigen::Matrix4d(jtj.diagonal().asDiagonal());
    const Eigen::Vector4d step = aug.ldlt().solve(-g);
    const Eigen::VectorXd rn = residuals(p + step);
    if (rn.squaredNorm() < r.squaredNorm()) {
      p += step;
      lambda = std::max(lambda / 3.0, 1e-9);
      const bool done = r.squaredNorm() - rn.squaredNorm() < 1e-12 * r.squaredNorm();
      r = rn;
      if (done) break;
    } else {
      lambda *= 4.0;
    }
  }
  m = HfModel{std::exp(p(0)), std::exp(p(1)), std::exp(p(2)), std::exp(p(3))};
  theta << m.b1, m.b0, m.a1, m.a0;
  if (!(m.b1 > 0 && m.b0 > 0 && m.a1 > 0 && m.a0 > 0) || !theta.allFinite()) {
    throw ComputationFailed("HF fit: model is unstable or non-minimum-phase");
  }
  return m;
}

namespace {
// Magnitude smoothed over +-half bins (log domain): the band-edge tests see the response,
// not the scatter of single Welch bins.
std::vector<double> smoothed_db(const std::vector<std::complex<double>>& h, std::size_t half) {
  std::vector<double> out(h.size());
  for (std::size_t i = 0; i < h.size(); ++i) {
    const std::size_t a = i > half ? i - half : 0;
    const std::size_t b = std::min(h.size() - 1, i + half);
    double s = 0.0;
    for (std::size_t j = a; j <= b; ++j) s += 20.0 * std::log10(std::max(std::abs(h[j]), 1e-300));
    out[i] = s / static_cast<double>(b - a + 1);
  }
  return out;
}
}  // namespace

IdentificationResult identify(const DualStagePlant& plant, const IdentificationOptions& o) {
  IdentificationResult r;
  r.lf = measure_frf(plant, Channel::kPantograph, o.lf_amplitude_N, o);
  r.hf = measure_frf(plant, Channel::kHaptuator, o.hf_amplitude_V, o);
  // LF static gain (eq. 3.5): mean magnitude over the reference band.
  double sum = 0.0;
  int cnt = 0;
  for (std::size_t i = 0; i < r.lf.f_Hz.size(); ++i) {
    if (r.lf.f_Hz[i] >= o.lf_ref_lo_Hz && r.lf.f_Hz[i] <= o.lf_ref_hi_Hz) {
      sum += std::abs(r.lf.h[i]);
      ++cnt;
    }
  }
  if (cnt == 0) throw ComputationFailed("LF identification: empty reference band");
  r.lf_gain = sum / cnt;
  const double tol_db = o.flat_tol_dB;
  const std::vector<double> lf_db = smoothed_db(r.lf.h, 4);
  const std::vector<double> hf_db = smoothed_db(r.hf.h, 4);
  const double lf_gain_db = 20.0 * std::log10(r.lf_gain);
  // LF flat band: from the reference band upward until the first bin outside tolerance.
  r.lf_flat_upper_Hz = o.lf_ref_hi_Hz;
  for (std::size_t i = 0; i < r.lf.f_Hz.size(); ++i) {
    if (r.lf.f_Hz[i] < o.lf_ref_lo_Hz) continue;
    if (std::abs(lf_db[i] - lf_gain_db) > tol_db) break;
    r.lf_flat_upper_Hz = r.lf.f_Hz[i];
  }
  // HF model and the lower edge of its validity (downward from the fit band's top).
  r.hf_model = fit_second_order(r.hf, o.fit_lo_Hz, o.fit_hi_Hz, plant.params().dt_s);
  r.hf_valid_lower_Hz = o.fit_hi_Hz;
  for (std::size_t i = r.hf.f_Hz.size(); i-- > 0;) {
    if (r.hf.f_Hz[i] > o.fit_hi_Hz) continue;
    const double model_db = 20.0 * std::log10(std::abs(r.hf_model.response(r.hf.f_Hz[i])));
    if (std::abs(hf_db[i] - model_db) > tol_db) break;
    r.hf_valid_lower_Hz = r.hf.f_Hz[i];
  }
  if (r.hf_valid_lower_Hz >= r.lf_flat_upper_Hz) {
    throw ComputationFailed("identification: the channels do not overlap (HF valid from " +
                            std::to_string(r.hf_valid_lower_Hz) + " Hz, LF flat to " +
                            std::to_string(r.lf_flat_upper_Hz) + " Hz)");
  }
  // Cut-off (§3.3.2): as high as the Pantograph allows inside the overlap, on the 1/3-octave grid.
  r.cutoff_Hz = 0.0;
  for (double fc : table_3_4_centres_Hz()) {
    if (fc <= r.lf_flat_upper_Hz && fc >= r.hf_valid_lower_Hz) r.cutoff_Hz = fc;
  }
  if (r.cutoff_Hz == 0.0) r.cutoff_Hz = r.lf_flat_upper_Hz;
  return r;
}

RenderPipelineParams pipeline_from(const IdentificationResult& id, RenderPipelineParams base) {
  base.cutoff_Hz = id.cutoff_Hz;
  base.lf_gain_m_s2_per_N = id.lf_gain;
  base.hf_num = {id.hf_model.b1, id.hf_model.b0};
  base.hf_den = {1.0, id.hf_model.a1, id.hf_model.a0};
  base.validate();
  return base;
}

}  // namespace mc::haptics
