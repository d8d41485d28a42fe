#include "microcobot/haptics/render_pipeline.h"

#include <cmath>
#include <numbers>

#include "microcobot/core/error.h"
#include "microcobot/dsp/butterworth.h"
#include "microcobot/dsp/zpk.h"

namespace mc::haptics {

namespace {

using cd = std::complex<double>;

// C_HF in the z domain: the inverse model's zeros and pole are mapped exactly (matched z,
// z = e^{sT}), F(f_max) is a bilinear (prewarped) Butterworth low-pass, and the gain is set
// so that |C_HF| equals the analog eq. 3.8 at the geometric centre of the HF band. The
// matched mapping keeps the inverse's magnitude within 0.05 dB of the analog up to 1.25 kHz
// at 10 kHz (tested), where a plain bilinear transform warps the 340 Hz zero pair.
// Analog C_HF(j 2 pi f) = K_sys / G_HF(j 2 pi f) x F(f_max) (eq. 3.8), F a 2nd-order
// Butterworth low-pass at f_max with unit DC gain.
cd c_hf_eq38(const RenderPipelineParams& p, double f_Hz) {
  const cd s(0.0, 2.0 * std::numbers::pi * f_Hz);
  const cd wf = 2.0 * std::numbers::pi * p.f_max_Hz;
  return p.k_sys_m_s2_per_N / p.hf_model().response(f_Hz) * wf * wf /
         (s * s + std::sqrt(2.0) * wf * s + wf * wf);
}

dsp::Sos design_c_hf(const RenderPipelineParams& p) {
  const HfModel m = p.hf_model();
  const double t = 1.0 / p.fs_Hz;
  const cd disc = std::sqrt(cd(m.a1 * m.a1 - 4.0 * m.a0, 0.0));
  const cd z1 = 0.5 * (-m.a1 + disc), z2 = 0.5 * (-m.a1 - disc);
  const double pole = -m.b0 / m.b1;
  dsp::Zpk inv;
  inv.z = {std::exp(z1 * t), std::exp(z2 * t)};
  // The matched mapping of two zeros over one pole droops as sinc(w T / 2), and so does the
  // zero-order hold that feeds the amplifier; a real pole at z = -(2 - sqrt 3) lifts the
  // response by 1 + (w T)^2 / 12 and cancels both to second order.
  inv.p = {std::exp(cd(pole * t, 0.0)), cd(-(2.0 - std::sqrt(3.0)), 0.0)};
  inv.k = 1.0;
  dsp::Zpk f = dsp::butter_zpk(2, p.f_max_Hz, p.fs_Hz, dsp::FilterType::kLowPass);
  dsp::Zpk all;
  all.z = inv.z;
  all.z.insert(all.z.end(), f.z.begin(), f.z.end());
  all.p = inv.p;
  all.p.insert(all.p.end(), f.p.begin(), f.p.end());
  all.k = f.k;
  // Gain: C_HF followed by the DAC hold matches the analog eq. 3.8 at the band centre.
  const double fref = std::sqrt(p.cutoff_Hz * 1250.0);
  const cd zr = std::exp(cd(0.0, 2.0 * std::numbers::pi * fref * t));
  cd hd = all.k;
  for (const cd& z : all.z) hd *= (zr - z);
  for (const cd& pp : all.p) hd /= (zr - pp);
  const cd ha = c_hf_eq38(p, fref);
  const double x = std::numbers::pi * fref * t;
  all.k *= std::abs(ha) / (std::abs(hd) * std::sin(x) / x);  // the ZOH droop is compensated
  return dsp::zpk2sos(all);
}

}  // namespace

std::complex<double> HfModel::response(double f_Hz) const {
  const cd s(0.0, 2.0 * std::numbers::pi * f_Hz);
  return (b1 * s + b0) / (s * s + a1 * s + a0);
}

HfModel RenderPipelineParams::hf_model() const {
  HfModel m;
  m.b1 = hf_num[0];
  m.b0 = hf_num[1];
  m.a1 = hf_den[1] / hf_den[0];
  m.a0 = hf_den[2] / hf_den[0];
  m.b1 /= hf_den[0];
  m.b0 /= hf_den[0];
  return m;
}

int RenderPipelineParams::hf_delay_samples() const {
  return static_cast<int>(std::lround(hf_delay_s * fs_Hz));
}

void RenderPipelineParams::validate() const {
  require_positive(fs_Hz, "fs_Hz");
  require(cutoff_Hz > 0.0 && cutoff_Hz < 0.5 * fs_Hz, "cutoff_Hz", "must be in (0, fs/2)", cutoff_Hz);
  require_positive(k_sys_m_s2_per_N, "k_sys_m_s2_per_N");
  require_positive(lf_gain_m_s2_per_N, "lf_gain_m_s2_per_N");
  require(hf_num.size() == 2, "hf_num", "must be [b1, b0]");
  require(hf_den.size() == 3, "hf_den", "must be [a2, a1, a0]");
  for (double v : hf_num) require(std::isfinite(v) && v > 0.0, "hf_num", "must be > 0 (minimum phase)", v);
  for (double v : hf_den) require(std::isfinite(v) && v > 0.0, "hf_den", "must be > 0 (stable)", v);
  require(f_max_Hz > cutoff_Hz && f_max_Hz < 0.5 * fs_Hz, "f_max_Hz", "must be in (cutoff_Hz, fs/2)",
          f_max_Hz);
  require(std::isfinite(hf_delay_s) && hf_delay_s >= 0.0 && hf_delay_s * fs_Hz < kMaxDelaySamples + 0.5,
          "hf_delay_s", "must be in [0, " + std::to_string(kMaxDelaySamples) + " / fs_Hz]", hf_delay_s);
  require_positive(max_force_N, "max_force_N");
  require_positive(max_voltage_V, "max_voltage_V");
}

RenderPipeline::RenderPipeline(const RenderPipelineParams& params)
    : params_(params),
      lp_((params.validate(),
           dsp::linkwitz_riley(4, params.cutoff_Hz, params.fs_Hz, dsp::FilterType::kLowPass))),
      hp_(dsp::linkwitz_riley(4, params.cutoff_Hz, params.fs_Hz, dsp::FilterType::kHighPass)),
      c_hf_(design_c_hf(params)),
      c_lf_(params.k_sys_m_s2_per_N / params.lf_gain_m_s2_per_N),
      delay_(static_cast<unsigned>(params.hf_delay_samples())) {}

void RenderPipeline::reset() {
  lp_.reset();
  hp_.reset();
  c_hf_.reset();
  delay_line_.fill(0.0);
  head_ = 0;
}

std::complex<double> RenderPipeline::lowpass_response(double f_Hz) const {
  return dsp::sos_response(lp_.sections(), f_Hz, params_.fs_Hz);
}
std::complex<double> RenderPipeline::highpass_response(double f_Hz) const {
  return dsp::sos_response(hp_.sections(), f_Hz, params_.fs_Hz);
}
std::complex<double> RenderPipeline::c_hf_response(double f_Hz) const {
  const double w = 2.0 * std::numbers::pi * f_Hz / params_.fs_Hz;
  return dsp::sos_response(c_hf_.sections(), f_Hz, params_.fs_Hz) *
         std::exp(cd(0.0, -w * static_cast<double>(delay_)));
}
std::complex<double> RenderPipeline::c_hf_analog(double f_Hz) const { return c_hf_eq38(params_, f_Hz); }

}  // namespace mc::haptics
