#include "microcobot/studies/identification_figures.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "microcobot/stickslip/ident_all.h"
#include "microcobot/stickslip/ident_synthetic.h"

namespace mc::studies {
namespace {

namespace ss = mc::stickslip;

/// At most `max` points of a curve (plots stay light).
report::Series series(std::string name, const std::vector<double>& x, const std::vector<double>& y,
                      double yscale = 1.0, std::size_t max = 4000, bool points = false) {
  report::Series s;
  s.name = std::move(name);
  s.points = points;
  const std::size_t step = std::max<std::size_t>(1, x.size() / max);
  for (std::size_t i = 0; i < x.size(); i += step) {
    s.x.push_back(x[i]);
    s.y.push_back(y[i] * yscale);
  }
  return s;
}

/// A PSD on log axes: its positive bins above DC.
report::Series psd_series(std::string name, const dsp::Spectrum& psd) {
  std::vector<double> f, p;
  for (std::size_t i = 1; i < psd.f_Hz.size(); ++i) {
    if (psd.value[i] > 0) {
      f.push_back(psd.f_Hz[i]);
      p.push_back(psd.value[i]);
    }
  }
  return series(std::move(name), f, p);
}

}  // namespace

void pe_section(report::Report& rep, const ss::MeasuredRecord& rec, const ss::PeModesResult& r) {
  rep.section(
      "identification: PE modes (thesis 2.5.2.1, Fig. 2.10)",
      "Step response of the PE without slider. The PSD of the free response gives the resonances; a "
      "separable nonlinear least-squares fit of the time response gives frequencies, damping ratios and the "
      "split of the static gain between the two modes.");
  rep.add_result("mode a frequency", r.a.frequency_Hz, "Hz");
  rep.add_result("mode a damping ratio", r.a.damping_ratio);
  rep.add_result("mode b frequency", r.b.frequency_Hz, "Hz");
  rep.add_result("mode b damping ratio", r.b.damping_ratio);
  rep.add_result("gain fraction phi (mode a)", r.gain_fraction_a);
  rep.add_result("fit RMS residual", r.rms_m, "m");
  rep.add_figure({"PSD of the PE free response",
                  "Resonance peaks seed the time-domain fit.",
                  {"Frequency", "Hz", true},
                  {"PSD", "m^2/Hz", true},
                  {psd_series("measured", r.psd)}});
  rep.add_figure({"PE step response",
                  "Measured (with sensor effects) and identified model.",
                  {"Time", "s"},
                  {"x1", "m"},
                  {series("measured", rec.t_s, rec.x_m), series("model", rec.t_s, r.fitted_m)}});
}

void friction_section(report::Report& rep, const ss::MeasuredRecord& rec, const ss::FrictionModesResult& r) {
  rep.section(
      "identification: asperity modes (thesis 2.5.2.1, Fig. 2.11)",
      "Step response of the actuator in scanning mode (no slip). Each asperity's contact stiffness and "
      "damping (eq. 2.20-2.21) gives one mode of the slider; the fit also gives the slider's mass split.");
  rep.add_result("asperity a mode", r.a.frequency_Hz, "Hz");
  rep.add_result("asperity a damping ratio", r.a.damping_ratio);
  rep.add_result("asperity b mode", r.b.frequency_Hz, "Hz");
  rep.add_result("asperity b damping ratio", r.b.damping_ratio);
  rep.add_result("rho0_a", r.params.rho0_a_N_m, "N/m");
  rep.add_result("rho1_a", r.params.rho1_a_N_s_m, "N s/m");
  rep.add_result("rho0_b", r.params.rho0_b_N_m, "N/m");
  rep.add_result("rho1_b", r.params.rho1_b_N_s_m, "N s/m");
  rep.add_result("mass fraction c_a", r.mass_fraction_a);
  rep.add_result("fit RMS residual", r.rms_m, "m");
  rep.add_figure({"PSD of the actuator's free response",
                  "The two asperity modes.",
                  {"Frequency", "Hz", true},
                  {"PSD", "m^2/Hz", true},
                  {psd_series("measured", r.psd)}});
  rep.add_figure({"Actuator step response (scanning mode)",
                  "Measured and identified elastic-phase model.",
                  {"Time", "s"},
                  {"x2", "m"},
                  {series("measured", rec.t_s, rec.x_m), series("model", rec.t_s, r.fitted_m)}});
}

void hysteresis_section(report::Report& rep, const ss::MeasuredRecord& rec, const ss::HysteresisResult& r) {
  rep.section(
      "identification: PI hysteresis (thesis 2.5.2.2, Fig. 2.12)",
      "Play-operator thresholds on a non-uniform partition of the input range; weights by non-negative "
      "least squares; the inverse PI model for feed-forward.");
  rep.add_result("operators", static_cast<double>(r.pi.size()));
  rep.add_result("static gain g", r.static_gain_m_V, "m/V");
  rep.add_result("loop RMS error", r.rms_m, "m");
  rep.add_result("loop RMS error / stroke", r.rms_fraction);
  rep.add_result("max |H^-1(H(U)) - U|", r.inverse_max_error_V, "V");
  std::vector<double> u(rec.u_V.begin() + static_cast<long>(r.first_fitted), rec.u_V.end());
  std::vector<double> xm(rec.x_m.begin() + static_cast<long>(r.first_fitted), rec.x_m.end());
  std::vector<double> xf(r.fitted_m.begin() + static_cast<long>(r.first_fitted), r.fitted_m.end());
  rep.add_figure({"Hysteresis loop x2(U)",
                  "Measured and PI model.",
                  {"Voltage", "V"},
                  {"x2", "m"},
                  {series("measured", u, xm, 1.0, 3000, true), series("PI model", u, xf)}});
  std::vector<double> uu, hh, back;
  ss::PiState sf = ss::make_pi_state(r.pi), si = ss::make_pi_state(r.inverse);
  for (int k = 0; k <= 400; ++k) {
    const double t = static_cast<double>(k) / 400.0;
    const double v = 100.0 * 0.5 * (1.0 - std::cos(2 * M_PI * 1.5 * t)) * (1.0 - 0.5 * t);
    uu.push_back(v);
    hh.push_back(ss::pi_update(r.pi, sf, v));
    back.push_back(ss::pi_update(r.inverse, si, hh.back()));
  }
  rep.add_figure({"PI model and its inverse",
                  "H(U) and H^-1(H(U)) = U on a decaying excitation.",
                  {"Voltage U", "V"},
                  {"Equivalent voltage", "V"},
                  {series("H(U)", uu, hh), series("H^-1(H(U))", uu, back)}});
}

void breakaway_section(report::Report& rep, const ss::BreakawayResult& r) {
  rep.section("identification: break-away strain (thesis 2.5.2.3, Fig. 2.13)",
              "z_ba of each sawtooth run, matching the measured mean velocity with the simulated one.");
  rep.add_result("runs", static_cast<double>(r.runs.size()));
  rep.add_result("skipped runs", static_cast<double>(r.skipped));
  const auto& t = r.table;
  for (std::size_t j = 0; j < t.frequencies_Hz.size(); ++j) {
    std::vector<double> zf, zb;
    for (std::size_t i = 0; i < t.amplitudes_V.size(); ++i) {
      zf.push_back(t.forward_m[i][j]);
      zb.push_back(t.backward_m[i][j]);
    }
    rep.add_figure(
        {fmt::format("z_ba versus amplitude at {:g} Hz", t.frequencies_Hz[j]),
         "Identified table (cells without a stepping run: interpolated between fitted cells of their "
         "frequency, extrapolated along amplitude below them).",
         {"Sawtooth amplitude", "V"},
         {"z_ba", "m"},
         {series("z_ba(+) forward", t.amplitudes_V, zf, 1.0, 4000, true),
          series("z_ba(-) backward", t.amplitudes_V, zb, 1.0, 4000, true)}});
  }
  std::vector<double> vm, vs;
  for (const auto& run : r.runs) {
    if (!run.ok) continue;
    vm.push_back(run.v_measured_m_s);
    vs.push_back(run.v_simulated_m_s);
  }
  if (!vm.empty()) {
    rep.add_figure({"Simulated versus measured mean velocity",
                    "Each point one run (both directions).",
                    {"measured velocity", "m/s"},
                    {"simulated velocity", "m/s"},
                    {series("runs", vm, vs, 1.0, 4000, true), series("identity", vm, vm, 1.0, 4000, true)}});
  }
}

void identification_figures(report::Report& rep) {
  const ss::StickSlipParams truth;
  ss::CampaignPlan plan;
  plan.amplitudes_V = {50, 80};
  plan.frequencies_Hz = {500};
  plan.sawtooth_periods = 4;
  const auto dir = std::filesystem::temp_directory_path() / fmt::format("mc-identify-report-{}", ::getpid());
  ss::write_campaign(dir, truth, plan, ss::SensorEffects{});
  ss::IdentifyAllOptions io;
  io.breakaway.scan_points = 8;
  ss::IdentifyAllResult r;
  try {
    r = ss::identify_all(dir, truth, io);
  } catch (...) {
    std::filesystem::remove_all(dir);
    throw;
  }
  rep.section(
      "identification of a stick-slip axis (thesis 2.5)",
      "A synthetic campaign of the default axis (simulated, with 0.1 nm quantisation, 1 nm RMS position "
      "noise and 1% voltage noise) identified by `microcobot identify all`; reproduce with `microcobot "
      "identify synth --out DIR && microcobot identify all --in DIR --out OUT`.");
  if (r.pe) pe_section(rep, ss::read_record(dir / "pe_step.csv"), *r.pe);
  friction_section(rep, ss::read_record(dir / "step.csv"), r.friction);
  hysteresis_section(rep, ss::read_record(dir / "sine.csv"), r.hysteresis);
  breakaway_section(rep, r.breakaway);
  std::filesystem::remove_all(dir);
}

}  // namespace mc::studies
