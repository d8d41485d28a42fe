#include "microcobot/studies/experiments.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"
#include "microcobot/dsp/peaks.h"

namespace mc::studies {

namespace {

/// Runs a step of `amplitude_V` (edge `slew`) applied half-way through `n` samples at `fs`, and
/// returns the response and the PSD of its transient (one Hann segment centred on the step,
/// zero-padded 4x) with its two dominant peaks above f_min.
StepSpectrumResult step_spectrum(const stickslip::StickSlipParams& p, double amplitude_V, double slew_V_s,
                                 double fs, std::size_t n, double dt, double f_min) {
  const stickslip::ActuatorModel m(p, dt);
  const int every = static_cast<int>(std::llround(1.0 / (fs * dt)));
  stickslip::Waveform w;
  w.kind = stickslip::WaveKind::kStep;
  w.amplitude_V = amplitude_V;
  w.slew_rate_V_s = slew_V_s;
  w.validate(p.drive);
  // Rest before the step, then the step.
  const double t_pre = static_cast<double>(n / 2) / fs;
  stickslip::ActuatorState s = m.initial_state();
  m.set_operating_point(s, amplitude_V, p.breakaway.frequencies_Hz.front(), stickslip::Direction::kForward);
  StepSpectrumResult r;
  const long steps = static_cast<long>(n) * every;
  for (long k = 0; k < steps; ++k) {
    if (k % every == 0) {
      r.response.t_s.push_back(s.t_s - t_pre);
      r.response.u_V.push_back(s.u_V);
      r.response.x1_m.push_back(s.x1_m());
      r.response.x2_m.push_back(m.slider_position(s));
    }
    m.step(s, w.segment(static_cast<double>(k) * dt - t_pre, dt));
    if (s.diverged) throw ComputationFailed("step experiment diverged (NaN/Inf)");
  }
  const auto& x = p.slider.attached ? r.response.x2_m : r.response.x1_m;
  std::vector<double> e(x.size());
  const double x0 = x.front(), xf = x.back();
  for (std::size_t i = 0; i < x.size(); ++i) e[i] = x[i] - (r.response.t_s[i] < 0.0 ? x0 : xf);
  dsp::WelchOptions o;
  o.fs_Hz = fs;
  o.nperseg = n;
  o.nfft = 4 * n;
  o.detrend = dsp::Detrend::kNone;
  r.psd = dsp::welch(e, o);
  std::vector<double> db(r.psd.value.size());
  for (std::size_t i = 0; i < db.size(); ++i) db[i] = 10.0 * std::log10(std::max(r.psd.value[i], 1e-300));
  dsp::PeakOptions po;
  po.min_prominence = 3.0;
  auto peaks = dsp::find_peaks_xy(r.psd.f_Hz, db, po);
  peaks.erase(std::remove_if(peaks.begin(), peaks.end(), [&](const dsp::Peak& pk) { return pk.x < f_min; }),
              peaks.end());
  std::sort(peaks.begin(), peaks.end(),
            [](const dsp::Peak& a, const dsp::Peak& b) { return a.height > b.height; });
  if (peaks.size() > 2) peaks.resize(2);
  for (const auto& pk : peaks) r.peaks_Hz.push_back(pk.x);
  std::sort(r.peaks_Hz.begin(), r.peaks_Hz.end());
  return r;
}

double mean_over(const std::vector<double>& x, std::size_t from, std::size_t count) {
  double s = 0.0;
  for (std::size_t i = from; i < from + count; ++i) s += x[i];
  return s / static_cast<double>(count);
}

}  // namespace

StepSpectrumResult run_pe_step(const stickslip::StickSlipParams& params) {
  stickslip::StickSlipParams p = params;
  p.slider.attached = false;
  return step_spectrum(p, 90.0, 1e8, 1e6, 1024, 1e-6, 10e3);
}

StepSpectrumResult run_actuator_step(const stickslip::StickSlipParams& params) {
  return step_spectrum(params, 40.0, params.drive.slew_rate_V_s, 25e3, 1024, 1e-5, 100.0);
}

std::vector<HysteresisLoop> run_hysteresis(const stickslip::StickSlipParams& params) {
  const stickslip::ActuatorModel m(params);
  const double conditions[][2] = {{50, 40},  {50, 25},  {250, 40},  {250, 25},
                                  {595, 25}, {595, 14}, {1633, 14}, {1633, 12}};
  std::vector<HysteresisLoop> loops;
  for (const auto& c : conditions) {
    const stickslip::Waveform w = stickslip::make_waveform(stickslip::WaveKind::kSine, c[1], c[0],
                                                           stickslip::Direction::kForward, params.drive);
    const int periods = c[0] < 100 ? 3 : 8;
    const double period = 1.0 / c[0];
    stickslip::ActuatorState s = m.initial_state();
    const stickslip::Trajectory tr = simulate(m, w, periods * period, 1, &s);
    HysteresisLoop l;
    l.frequency_Hz = c[0];
    l.amplitude_V = c[1];
    const std::size_t per = static_cast<std::size_t>(std::llround(period / m.dt_s()));
    const std::size_t start = tr.x2_m.size() - per - 1;
    const double lo = *std::min_element(tr.x2_m.begin() + static_cast<long>(start), tr.x2_m.end());
    const double hi = *std::max_element(tr.x2_m.begin() + static_cast<long>(start), tr.x2_m.end());
    for (std::size_t i = start; i < tr.x2_m.size(); ++i) {
      l.u_V.push_back(tr.u_V[i]);
      l.x2_m.push_back(tr.x2_m[i] - lo);
    }
    for (std::size_t i = 1; i < l.u_V.size(); ++i) {
      l.area_V_m += 0.5 * (l.u_V[i - 1] * l.x2_m[i] - l.u_V[i] * l.x2_m[i - 1]);
    }
    l.range_m = hi - lo;
    loops.push_back(std::move(l));
  }
  return loops;
}

SawtoothCase run_sawtooth(const stickslip::StickSlipParams& params, double amplitude_V, double frequency_Hz,
                          stickslip::Direction direction, int periods) {
  require(periods >= 1, "periods", "must be >= 1", periods);
  const stickslip::ActuatorModel m(params);
  const stickslip::Waveform w = stickslip::make_waveform(stickslip::WaveKind::kSawtooth, amplitude_V,
                                                         frequency_Hz, direction, params.drive);
  const double period = 1.0 / frequency_Hz;
  const stickslip::Trajectory tr = simulate(m, w, (periods + 2) * period, 1);
  const auto per = static_cast<std::size_t>(std::llround(period / m.dt_s()));
  require(per >= 4, "frequency_Hz", "period too short for integrator.dt_s", frequency_Hz);
  SawtoothCase c;
  c.amplitude_V = amplitude_V;
  c.frequency_Hz = frequency_Hz;
  c.direction = direction;
  c.net_displacement_m =
      mean_over(tr.x2_m, per * static_cast<std::size_t>(periods + 1), per) - mean_over(tr.x2_m, per, per);
  c.velocity_m_s = c.net_displacement_m / (periods * period);
  c.stroke_m = params.pe.static_gain_m_V * amplitude_V;
  const double sign = direction == stickslip::Direction::kForward ? 1.0 : -1.0;
  c.stepping = sign * c.net_displacement_m >= 0.02 * c.stroke_m;
  const std::size_t every = std::max<std::size_t>(1, tr.t_s.size() / 4000);
  for (std::size_t i = 0; i < tr.t_s.size(); i += every) {
    c.trajectory.t_s.push_back(tr.t_s[i]);
    c.trajectory.u_V.push_back(tr.u_V[i]);
    c.trajectory.x1_m.push_back(tr.x1_m[i]);
    c.trajectory.x2_m.push_back(tr.x2_m[i]);
  }
  return c;
}

std::vector<SawtoothCase> run_scanning(const stickslip::StickSlipParams& params) {
  std::vector<SawtoothCase> out;
  for (double f : {50.0, 100.0, 500.0}) {
    for (stickslip::Direction d : {stickslip::Direction::kForward, stickslip::Direction::kBackward})
      out.push_back(run_sawtooth(params, 20.0, f, d));
  }
  return out;
}

std::vector<SawtoothCase> run_stepping(const stickslip::StickSlipParams& params) {
  std::vector<SawtoothCase> out;
  for (double a : {40.0, 60.0}) {
    for (double f : {50.0, 100.0, 500.0}) {
      for (stickslip::Direction d : {stickslip::Direction::kForward, stickslip::Direction::kBackward})
        out.push_back(run_sawtooth(params, a, f, d));
    }
  }
  return out;
}

ThresholdResult run_threshold(const stickslip::StickSlipParams& params, double frequency_Hz) {
  ThresholdResult r;
  r.frequency_Hz = frequency_Hz;
  for (stickslip::Direction d : {stickslip::Direction::kForward, stickslip::Direction::kBackward}) {
    double lo = 5.0, hi = params.drive.max_V - params.drive.min_V;
    if (run_sawtooth(params, lo, frequency_Hz, d).stepping) {
      (d == stickslip::Direction::kForward ? r.forward_V : r.backward_V) = lo;
      continue;
    }
    if (!run_sawtooth(params, hi, frequency_Hz, d).stepping) {
      throw ComputationFailed("no stepping up to " + std::to_string(hi) + " V " + to_string(d));
    }
    while (hi - lo > 0.25) {
      const double mid = 0.5 * (lo + hi);
      (run_sawtooth(params, mid, frequency_Hz, d).stepping ? hi : lo) = mid;
    }
    (d == stickslip::Direction::kForward ? r.forward_V : r.backward_V) = hi;
  }
  return r;
}

std::vector<PsdCase> run_psd(const stickslip::StickSlipParams& params) {
  const stickslip::ActuatorModel m(params);
  std::vector<PsdCase> out;
  for (const auto& c : {std::pair{20.0, 500.0}, std::pair{40.0, 50.0}}) {
    const stickslip::Waveform w = stickslip::make_waveform(stickslip::WaveKind::kSawtooth, c.first, c.second,
                                                           stickslip::Direction::kForward, params.drive);
    const int every = static_cast<int>(std::llround(1.0 / (25e3 * m.dt_s())));
    const stickslip::Trajectory tr = simulate(m, w, 0.5, std::max(every, 1));
    PsdCase pc;
    pc.amplitude_V = c.first;
    pc.frequency_Hz = c.second;
    dsp::WelchOptions o;
    o.fs_Hz = 1.0 / (m.dt_s() * std::max(every, 1));
    o.nperseg = 4096;
    pc.psd = dsp::welch(tr.x2_m, o);
    std::size_t best = 1;
    for (std::size_t i = 1; i < pc.psd.value.size(); ++i) {
      if (pc.psd.value[i] > pc.psd.value[best]) best = i;
    }
    pc.dominant_peak_Hz = pc.psd.f_Hz[best];
    out.push_back(std::move(pc));
  }
  return out;
}

std::vector<std::string> experiment_names() {
  return {"pe-step", "actuator-step", "hysteresis", "scanning", "stepping", "threshold", "psd"};
}

}  // namespace mc::studies
