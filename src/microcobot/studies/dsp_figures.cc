#include "microcobot/studies/dsp_figures.h"

#include <algorithm>
#include <cmath>
#include <complex>

#include <fmt/format.h>

#include "microcobot/dsp/butterworth.h"
#include "microcobot/dsp/signals.h"
#include "microcobot/dsp/welch.h"

namespace mc::studies {

void dsp_figures(report::Report& r) {
  r.section("Signal and system toolkit",
            "Linkwitz-Riley LR4 crossovers at 200 Hz and 10 kHz sampled at 50 kHz (thesis Fig. 3.8, "
            "the split between Pantograph and Haptuator), the magnitude of their sum (an all-pass: "
            "|LP + HP| = 1), the Welch PSD of a 10 kHz PRBS and the first values of an MLS.");
  const double fs = 50000.0;
  report::Figure fig{"LR4 crossover magnitudes",
                     "Low- and high-pass outputs and |LP + HP|.",
                     {"Frequency", "Hz", true},
                     {"Magnitude", "dB", false},
                     {}};
  double worst = 0.0;
  for (double fc : {200.0, 10000.0}) {
    const auto x = dsp::linkwitz_riley_crossover(4, fc, fs);
    report::Series lp{fmt::format("LP {} Hz", fc), {}, {}}, hp{fmt::format("HP {} Hz", fc), {}, {}},
        sum{fmt::format("|LP+HP| {} Hz", fc), {}, {}};
    for (double f = 10.0; f < fs / 2; f *= 1.05) {
      const auto l = dsp::sos_response(x.low, f, fs), h = dsp::sos_response(x.high, f, fs);
      lp.x.push_back(f);
      lp.y.push_back(20 * std::log10(std::max(std::abs(l), 1e-12)));
      hp.x.push_back(f);
      hp.y.push_back(20 * std::log10(std::max(std::abs(h), 1e-12)));
      sum.x.push_back(f);
      sum.y.push_back(20 * std::log10(std::abs(l + h)));
      worst = std::max(worst, std::abs(std::abs(l + h) - 1.0));
    }
    fig.series.push_back(lp);
    fig.series.push_back(hp);
    fig.series.push_back(sum);
  }
  r.add_figure(fig);
  r.add_result("max | |LP+HP| - 1 | (LR4, 10 Hz..25 kHz)", worst);
  const double fsp = 10000.0;
  const auto u = dsp::prbs(15, 1 << 16, 1, 1.0);
  dsp::WelchOptions o;
  o.fs_Hz = fsp;
  o.nperseg = 1024;
  const auto p = dsp::welch(u, o);
  report::Figure psd{"Welch PSD of a PRBS",
                     "+-1 PRBS (15 bits) at 10 kHz: flat at 2/fs = 2e-4 V^2/Hz.",
                     {"Frequency", "Hz", true},
                     {"PSD", "V^2/Hz", true},
                     {}};
  report::Series s{"PRBS", {}, {}};
  for (std::size_t k = 1; k < p.f_Hz.size(); ++k) {
    s.x.push_back(p.f_Hz[k]);
    s.y.push_back(std::max(p.value[k], 1e-12));
  }
  psd.series.push_back(s);
  r.add_figure(psd);
  const auto m = dsp::max_len_seq(6);
  report::Figure mf{"MLS (6 bits)",
                    "One period (63 values) of scipy's 6-bit MLS.",
                    {"Index", "", false},
                    {"Bit", "", false},
                    {}};
  report::Series ms{"MLS", {}, {}, true};
  for (std::size_t k = 0; k < m.size(); ++k) {
    ms.x.push_back(static_cast<double>(k));
    ms.y.push_back(m[k]);
  }
  mf.series.push_back(ms);
  r.add_figure(mf);
}

}  // namespace mc::studies
