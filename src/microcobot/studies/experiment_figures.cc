#include "microcobot/studies/experiment_figures.h"

#include <cmath>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "microcobot/core/error.h"
#include "microcobot/studies/experiments.h"

namespace mc::studies {
namespace {

namespace ss = mc::stickslip;
using report::Figure;
using report::Report;
using report::Series;

/// Drops non-positive values (log axes) and the DC bin.
Series log_series(const std::string& name, const dsp::Spectrum& s, double f_max = 1e300) {
  Series out{name, {}, {}, false};
  for (std::size_t i = 0; i < s.f_Hz.size(); ++i) {
    if (s.f_Hz[i] > 0 && s.f_Hz[i] <= f_max && s.value[i] > 0 && std::isfinite(s.value[i])) {
      out.x.push_back(s.f_Hz[i]);
      out.y.push_back(s.value[i]);
    }
  }
  return out;
}

nlohmann::json step_experiment(Report& r, const std::string& name, const StepSpectrumResult& res,
                               const std::string& what, const std::string& expected) {
  r.section(name, what + " Peaks of the transient's PSD: " +
                      fmt::format("{:.1f}", fmt::join(res.peaks_Hz, " Hz, ")) + " Hz (thesis: " + expected +
                      ").");
  for (std::size_t i = 0; i < res.peaks_Hz.size(); ++i)
    r.add_result(fmt::format("peak {}", i + 1), res.peaks_Hz[i], "Hz");
  const bool pe = name == "pe-step";
  Series x{pe ? "x1 (PE)" : "x2 (slider)", res.response.t_s, pe ? res.response.x1_m : res.response.x2_m,
           false};
  r.add_figure({name + " response",
                "Displacement after the step (t = 0).",
                {"Time", "s"},
                {"Displacement", "m"},
                {x}});
  r.add_figure({name + " PSD",
                "PSD of the transient x(t) - x(final), one Hann window centred on the step.",
                {"Frequency", "Hz", true},
                {"PSD", "m^2/Hz", true},
                {log_series("PSD", res.psd)}});
  return {{"peaks_Hz", res.peaks_Hz}};
}

Series periods_series(const SawtoothCase& c) {
  Series s{fmt::format("{:g} V {:g} Hz {}", c.amplitude_V, c.frequency_Hz, ss::to_string(c.direction)),
           {},
           {},
           false};
  const double x0 = c.trajectory.x2_m.front();
  for (std::size_t i = 0; i < c.trajectory.t_s.size(); ++i) {
    s.x.push_back(c.trajectory.t_s[i] * c.frequency_Hz);
    s.y.push_back(c.trajectory.x2_m[i] - x0);
  }
  return s;
}

nlohmann::json case_json(const SawtoothCase& c) {
  return {{"amplitude_V", c.amplitude_V},
          {"frequency_Hz", c.frequency_Hz},
          {"direction", ss::to_string(c.direction)},
          {"net_displacement_m", c.net_displacement_m},
          {"velocity_m_s", c.velocity_m_s},
          {"stroke_m", c.stroke_m},
          {"stepping", c.stepping}};
}

}  // namespace

nlohmann::json experiment_figures(const std::string& name, const stickslip::StickSlipParams& p,
                                  report::Report& r) {
  if (name == "pe-step") {
    return step_experiment(r, name, run_pe_step(p),
                           "Slider removed, 90 V step, 1 MHz sampling (thesis §2.5.2.1, Fig. 2.10).",
                           "64 and 118 kHz");
  }
  if (name == "actuator-step") {
    return step_experiment(r, name, run_actuator_step(p),
                           "40 V step, 25 kHz sampling (thesis §2.5.2.1, Fig. 2.11).", "595 and 1633 Hz");
  }
  if (name == "hysteresis") {
    const auto loops = run_hysteresis(p);
    r.section("hysteresis",
              "Sine 0..A V, last period, x2 against U (thesis §2.5.2.2, Fig. 2.12). The loops "
              "widen and tilt near the contact modes (595, 1633 Hz): the static PI hysteresis "
              "followed by the linear dynamics makes the loop rate dependent.");
    Figure f{"Hysteresis loops",
             "x2 (relative to its minimum) against the drive voltage.",
             {"Drive voltage", "V"},
             {"Slider displacement", "m"},
             {}};
    nlohmann::json arr = nlohmann::json::array();
    for (const auto& l : loops) {
      f.series.push_back(
          {fmt::format("{:g} Hz {:g} V", l.frequency_Hz, l.amplitude_V), l.u_V, l.x2_m, false});
      arr.push_back({{"frequency_Hz", l.frequency_Hz},
                     {"amplitude_V", l.amplitude_V},
                     {"area_V_m", l.area_V_m},
                     {"range_m", l.range_m}});
      r.add_result(fmt::format("range {:g} Hz {:g} V", l.frequency_Hz, l.amplitude_V), l.range_m, "m");
    }
    r.add_figure(std::move(f));
    return {{"loops", arr}};
  }
  if (name == "scanning" || name == "stepping") {
    const auto cases = name == "scanning" ? run_scanning(p) : run_stepping(p);
    r.section(name,
              name == "scanning"
                  ? "Sawtooth 20 V at 50, 100, 500 Hz, both directions (thesis Fig. 2.14): scanning "
                    "mode, no accumulated stepping (|net| over 20 periods < 2% of g*A)."
                  : "Sawtooth 40 and 60 V at 50, 100, 500 Hz, both directions (thesis Fig. 2.15-2.16): "
                    "stepping in the commanded direction, faster at 60 V, forward and backward differ.");
    nlohmann::json arr = nlohmann::json::array();
    for (double a : name == "scanning" ? std::vector<double>{20.0} : std::vector<double>{40.0, 60.0}) {
      Figure f{fmt::format("{} {:g} V", name, a),
               "Slider displacement against time in drive periods.",
               {"Time / period", ""},
               {"Slider displacement", "m"},
               {}};
      for (const auto& c : cases) {
        if (c.amplitude_V == a) f.series.push_back(periods_series(c));
      }
      r.add_figure(std::move(f));
    }
    for (const auto& c : cases) {
      arr.push_back(case_json(c));
      r.add_result(fmt::format("{} {:g} V {:g} Hz {}", name == "scanning" ? "net" : "velocity", c.amplitude_V,
                               c.frequency_Hz, ss::to_string(c.direction)),
                   name == "scanning" ? c.net_displacement_m : c.velocity_m_s,
                   name == "scanning" ? "m" : "m/s");
    }
    return {{"cases", arr}};
  }
  if (name == "threshold") {
    const auto t = run_threshold(p);
    r.section("threshold",
              "Smallest 50 Hz sawtooth amplitude that steps (|net| over 20 periods >= 2% of g*A "
              "in the commanded direction), bisection to 0.25 V (thesis §2.5.2: ~40 V).");
    r.add_result("forward threshold", t.forward_V, "V");
    r.add_result("backward threshold", t.backward_V, "V");
    Figure f{"Velocity against amplitude (50 Hz)",
             "Mean slider velocity over 20 periods.",
             {"Amplitude", "V"},
             {"Velocity", "m/s"},
             {}};
    for (auto d : {ss::Direction::kForward, ss::Direction::kBackward}) {
      Series s{ss::to_string(d), {}, {}, true};
      for (double a = 20; a <= 80; a += 5) {
        s.x.push_back(a);
        s.y.push_back(run_sawtooth(p, a, t.frequency_Hz, d).velocity_m_s);
      }
      f.series.push_back(std::move(s));
    }
    r.add_figure(std::move(f));
    return {{"forward_V", t.forward_V}, {"backward_V", t.backward_V}, {"frequency_Hz", t.frequency_Hz}};
  }
  if (name == "psd") {
    const auto cases = run_psd(p);
    r.section("psd",
              "PSD of the slider position (25 kHz, Welch 4096, 0.5 s) for 20 V / 500 Hz (scanning) and "
              "40 V / 50 Hz (stepping), thesis Fig. 2.17.");
    Figure f{"Output PSD", "Welch PSD of x2.", {"Frequency", "Hz", true}, {"PSD", "m^2/Hz", true}, {}};
    nlohmann::json arr = nlohmann::json::array();
    for (const auto& c : cases) {
      f.series.push_back(log_series(fmt::format("{:g} V {:g} Hz", c.amplitude_V, c.frequency_Hz), c.psd));
      arr.push_back({{"amplitude_V", c.amplitude_V},
                     {"frequency_Hz", c.frequency_Hz},
                     {"dominant_peak_Hz", c.dominant_peak_Hz}});
      r.add_result(fmt::format("dominant peak {:g} V {:g} Hz", c.amplitude_V, c.frequency_Hz),
                   c.dominant_peak_Hz, "Hz");
    }
    r.add_figure(std::move(f));
    return {{"cases", arr}};
  }
  throw UsageError("unknown experiment '" + name +
                   "' (pe-step, actuator-step, hysteresis, scanning, stepping, "
                   "threshold, psd)");
}

void stickslip_figures(report::Report& r) {
  const ss::StickSlipParams p;
  for (const auto& name : experiment_names()) experiment_figures(name, p, r);
}

}  // namespace mc::studies
