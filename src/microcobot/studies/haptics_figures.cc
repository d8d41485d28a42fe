#include "microcobot/studies/haptics_figures.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <span>
#include <vector>

#include <fmt/format.h>

namespace mc::studies {
namespace {

namespace hp = mc::haptics;
namespace mw = mc::microworld;
using report::Figure;
using report::Report;
using report::Series;

double db(std::complex<double> z) { return 20.0 * std::log10(std::max(std::abs(z), 1e-300)); }

Series frf_series(const std::string& name, const hp::ChannelFrf& f, double lo, double hi) {
  Series s{name, {}, {}, false};
  for (std::size_t i = 0; i < f.f_Hz.size(); ++i) {
    if (f.f_Hz[i] < lo || f.f_Hz[i] > hi) continue;
    s.x.push_back(f.f_Hz[i]);
    s.y.push_back(db(f.h[i]));
  }
  return s;
}

}  // namespace

void identify_report(Report& r, const hp::IdentificationResult& id) {
  r.section("Identification of the two channels (§3.4.2)",
            "PRBS at 10 kHz into one channel, the other passive; Welch H1 FRF of the handle "
            "acceleration with accelerometer noise. The Pantograph is a static gain up to its "
            "flat limit (eq. 3.5); the Haptuator is fitted by a 2nd-order model on 100-1000 Hz "
            "(eq. 3.6). Cut-off: the highest 1/3-octave frequency the Pantograph allows inside "
            "the overlap band (§3.3.2).");
  r.add_result("LF static gain", id.lf_gain, "m/s^2/N");
  r.add_result("LF flat (+-1 dB) up to", id.lf_flat_upper_Hz, "Hz");
  r.add_result("HF model valid from", id.hf_valid_lower_Hz, "Hz");
  r.add_result("cut-off", id.cutoff_Hz, "Hz");
  r.add_result("high-band alignment delay", id.hf_delay_s * 1e3, "ms");
  Figure lf{"Pantograph channel FRF (Fig. 3.10)",
            "H1 estimate and the static-gain model.",
            {"Frequency", "Hz", true},
            {"Magnitude", "dB re 1 m/s^2/N", false},
            {}};
  lf.series.push_back(frf_series("measured", id.lf, 10.0, 1500.0));
  Series lm{"model G0", {10.0, 1500.0}, {20 * std::log10(id.lf_gain), 20 * std::log10(id.lf_gain)}, false};
  lf.series.push_back(lm);
  r.add_figure(lf);
  Figure hf{"Haptuator channel FRF (Fig. 3.11)",
            "H1 estimate and the fitted 2nd-order model.",
            {"Frequency", "Hz", true},
            {"Magnitude", "dB re 1 m/s^2/V", false},
            {}};
  hf.series.push_back(frf_series("measured", id.hf, 10.0, 1500.0));
  Series hm{"fit (100-1000 Hz)", {}, {}, false};
  for (double f = 10.0; f <= 1500.0; f *= 1.03) {
    hm.x.push_back(f);
    hm.y.push_back(db(id.hf_model.response(f)));
  }
  hf.series.push_back(hm);
  r.add_figure(hf);
}

void evaluate_report(Report& r, const hp::EvaluationResult& ev, const hp::RenderPipelineParams& rp) {
  r.section("Crossover, compensation and evaluation (§3.3.2, §3.4.3, §3.5.1)",
            fmt::format("LR4 crossover at {:g} Hz; C_LF = K_sys/G_LF, C_HF = K_sys/G_HF x F(f_max) "
                        "with f_max = {:g} Hz, both from the identified models; the high band delayed by "
                        "{:g} ms so that the halves add in phase at the cut-off. Sine dwell at the "
                        "1/3-octave centres of Table 3.4 on the plant with accelerometer noise.",
                        rp.cutoff_Hz, rp.f_max_Hz, rp.hf_delay_s * 1e3));
  r.add_result("combined flatness (max-min, 63-1250 Hz)", ev.flatness_dB, "dB");
  const hp::RenderPipeline pipe(rp);
  Figure lr{"LR4 crossover (Fig. 3.8)",
            "Digital LR4 low-pass, high-pass and their sum.",
            {"Frequency", "Hz", true},
            {"Magnitude", "dB", false},
            {}};
  Series lp{"LP", {}, {}, false}, hpass{"HP", {}, {}, false}, sum{"LP + HP", {}, {}, false};
  for (double f = 10.0; f <= 4000.0; f *= 1.04) {
    lp.x.push_back(f);
    hpass.x.push_back(f);
    sum.x.push_back(f);
    lp.y.push_back(db(pipe.lowpass_response(f)));
    hpass.y.push_back(db(pipe.highpass_response(f)));
    sum.y.push_back(db(pipe.lowpass_response(f) + pipe.highpass_response(f)));
  }
  lr.series = {lp, hpass, sum};
  r.add_figure(lr);
  Figure e{"1/3-octave evaluation (Fig. 3.13)",
           "Handle acceleration over K_sys x force.",
           {"Frequency", "Hz", true},
           {"Magnitude", "dB", false},
           {}};
  e.series = {{"LF only", ev.fc_Hz, ev.lf_dB, true},
              {"HF only", ev.fc_Hz, ev.hf_dB, true},
              {"both", ev.fc_Hz, ev.combined_dB, true},
              {"Pantograph alone", ev.fc_Hz, ev.pantograph_dB, true}};
  r.add_figure(e);
}

TweezersOut run_tweezers_core(const HapticsParams& p, mw::TweezersScenario sc, double duration) {
  TweezersOut out;
  mw::TweezersOptions to;
  to.duration_s = duration;
  out.rec = mw::simulate_tweezers(p.trap, sc, to);
  const hp::DualStagePlant plant(p.plant);
  // The pipeline designed from the identified plant (as the demonstrator, §3.5.2).
  const auto id = hp::identify(plant, hp::IdentificationOptions{});
  const auto rp = hp::pipeline_from(id, p.pipeline);
  out.accel = hp::replay(plant, rp, out.rec.hand_force_N, 0.05, 11);
  const std::size_t skip = out.accel.size() / 10;  // drop the start-up transient
  out.stats = hp::gaussian_stats(std::span<const double>(out.accel).subspan(skip));
  // Corner of the trap from the bead's excursion in the trap, before any contact.
  std::vector<double> rel;
  for (std::size_t i = 0; i < out.rec.t_s.size(); ++i) {
    if (out.rec.contact_time_s >= 0.0 && out.rec.t_s[i] >= out.rec.contact_time_s) break;
    rel.push_back(out.rec.bead_y_m[i] - out.rec.trap_y_m[i]);
  }
  out.corner_Hz = mw::fit_corner_frequency(rel, to.record_rate_Hz);
  out.expected_corner_Hz = mw::OpticalTrap(p.trap).corner_frequency_Hz();
  if (sc == mw::TweezersScenario::kContact) {
    const auto it = std::max_element(out.rec.force_y_N.begin(), out.rec.force_y_N.end(),
                                     [](double a, double b) { return std::abs(a) < std::abs(b); });
    out.peak_time_s = out.rec.t_s[static_cast<std::size_t>(it - out.rec.force_y_N.begin())];
  }
  return out;
}

void tweezers_report(Report& r, const TweezersOut& t, bool contact) {
  r.section(
      contact ? "Optical tweezers: contact (Fig. 3.16)" : "Optical tweezers: Brownian motion (Fig. 3.15)",
      "Overdamped Langevin bead (r = 1.5 um, water, 300 K) in a linear trap; the measured "
      "force k (y - y_trap) is scaled to the hand (x 2e11) and replayed through the "
      "crossover pipeline and the plant; the handle accelerometer is recorded.");
  r.add_result("Gaussian fit R^2", t.stats.r2);
  r.add_result("kurtosis", t.stats.kurtosis);
  r.add_result("PSD corner", t.corner_Hz, "Hz");
  r.add_result("k / (2 pi gamma)", t.expected_corner_Hz, "Hz");
  if (!contact) {
    Figure h{"Handle acceleration histogram (Fig. 3.15)",
             "Density and the Gaussian with the same mean and std.",
             {"Acceleration", "m/s^2", false},
             {"Density", "s^2/m", false},
             {}};
    h.series = {{"histogram", t.stats.bin_centre, t.stats.density, true},
                {"Gaussian", t.stats.bin_centre, t.stats.gaussian, false}};
    r.add_figure(h);
  } else {
    r.add_result("contact time", t.rec.contact_time_s, "s");
    r.add_result("force peak time", t.peak_time_s, "s");
    Figure c{"Contact trace (Fig. 3.16)",
             "Hand force and handle acceleration.",
             {"Time", "s", false},
             {"Force / acceleration", "N, m/s^2", false},
             {}};
    Series f{"hand force (N)", {}, {}, false}, a{"handle acceleration (m/s^2)", {}, {}, false};
    for (std::size_t i = 0; i < t.rec.t_s.size(); i += 5) {
      f.x.push_back(t.rec.t_s[i]);
      f.y.push_back(t.rec.hand_force_N[i]);
      a.x.push_back(t.rec.t_s[i]);
      a.y.push_back(t.accel[i]);
    }
    c.series = {f, a};
    r.add_figure(c);
  }
}

void haptics_figures(Report& r) {
  const HapticsParams p;
  const hp::DualStagePlant plant(p.plant);
  const auto id = hp::identify(plant, hp::IdentificationOptions{});
  identify_report(r, id);
  const auto rp = hp::pipeline_from(id, p.pipeline);
  evaluate_report(r, hp::evaluate(plant, rp, hp::EvaluationOptions{}), rp);
  tweezers_report(r, run_tweezers_core(p, mw::TweezersScenario::kBrownian, 2.0), false);
  tweezers_report(r, run_tweezers_core(p, mw::TweezersScenario::kContact, 1.0), true);
}

}  // namespace mc::studies
