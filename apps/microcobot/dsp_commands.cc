// `microcobot dsp`: the signal and system toolkit on the command line.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include <cstdio>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "microcobot/core/mat_file.h"
#include "microcobot/dsp/butterworth.h"
#include "microcobot/dsp/octave.h"
#include "microcobot/dsp/signals.h"
#include "microcobot/dsp/welch.h"
#include "microcobot/ident/tf_fit.h"

namespace dsp_commands {
namespace {

using mc::cli::CommonOptions;

struct WelchFlags {
  std::size_t nperseg = 256;
  std::optional<std::size_t> noverlap;
  std::size_t nfft = 0;
  std::string detrend = "constant";
  std::string scaling = "density";
  double fs = 0;
};

void add_welch_flags(CLI::App* cmd, WelchFlags& w) {
  cmd->add_option("--fs", w.fs, "Sample rate (Hz)")->required()->check(mc::cli::PositiveNumber);
  cmd->add_option("--nperseg", w.nperseg, "Segment length (samples)")->check(mc::cli::PositiveNumber);
  cmd->add_option("--noverlap", w.noverlap, "Overlap (samples), default nperseg/2");
  cmd->add_option("--nfft", w.nfft, "FFT length >= nperseg (default nperseg)");
  cmd->add_option("--detrend", w.detrend, "constant|none")->check(CLI::IsMember({"constant", "none"}));
  cmd->add_option("--scaling", w.scaling, "density|spectrum")->check(CLI::IsMember({"density", "spectrum"}));
}

mc::dsp::WelchOptions to_options(const WelchFlags& w) {
  mc::dsp::WelchOptions o;
  o.fs_Hz = w.fs;
  o.nperseg = w.nperseg;
  o.noverlap = w.noverlap;
  o.nfft = w.nfft;
  o.detrend = mc::dsp::parse_detrend(w.detrend);
  o.scaling = mc::dsp::parse_scaling(w.scaling);
  return o;
}

/// Runs a Welch estimate of the columns `x` (and `y`) of `file`: an overflowing spectrum or a
/// signal too short is named by the file and column the user gave, a bad option by its flag, not
/// by the library's names (x, y, fs_Hz).
template <class F>
auto naming_columns(const std::string& file, const std::string& x, const std::string& y, F&& estimate) {
  try {
    std::optional<decltype(estimate())> result;
    mc::cli::naming_flags(
        {{"fs_Hz", "--fs"}, {"nperseg", "--nperseg"}, {"noverlap", "--noverlap"}, {"nfft", "--nfft"}}, [&] {
          try {
            result.emplace(estimate());
          } catch (const mc::InvalidParams& e) {
            if (e.field() != "x" && e.field() != "y") throw;
            const std::string what = e.what(), head = "invalid parameter " + e.field() + ": ";
            throw mc::InvalidInput(fmt::format("{}: column '{}': {}", file,
                                               mc::excerpt(e.field() == "x" ? x : y),
                                               what.rfind(head, 0) == 0 ? what.substr(head.size()) : what));
          }
        });
    return std::move(*result);
  } catch (const mc::dsp::SpectrumOverflow& e) {
    throw mc::ComputationFailed(fmt::format(
        "{}: column '{}': the power spectrum overflows (values up to {:g}; their squares exceed the largest "
        "double)",
        file, mc::excerpt(e.signal() == "x" ? x : y), e.max_abs()));
  }
}

std::vector<std::complex<double>> read_frf(const mc::CsvTable& t) {
  const auto& re = t.column("re");
  const auto& im = t.column("im");
  std::vector<std::complex<double>> h(re.size());
  for (std::size_t i = 0; i < h.size(); ++i) h[i] = {re[i], im[i]};
  return h;
}

using NamedColumn = std::pair<const char*, const std::vector<double>&>;

// A spectrum-like result: two columns, as JSON on stdout and as `csv_name` (or results.mat).
void write_two_columns(const mc::cli::CommonOptions& common, const char* csv_name, const NamedColumn& x,
                       const NamedColumn& y) {
  const nlohmann::json j{{x.first, x.second}, {y.first, y.second}};
  mc::CsvTable t;
  t.add_column(x.first, x.second);
  t.add_column(y.first, y.second);
  mc::cli::write_result_table(common, csv_name, t, j);
  mc::cli::emit(common, j);
}

void add_dsp(CLI::App& group) {
  group.require_subcommand(1);
  {
    struct O {
      CommonOptions common;
      int order = 2;
      double fc = 0, fs = 0;
      std::string type = "low";
    };
    auto o = std::make_shared<O>();
    auto* cmd =
        group.add_subcommand("butter", "Butterworth / Linkwitz-Riley LR4 design as second-order sections");
    cmd->add_option("--order", o->order, "Filter order (Butterworth 1..20; LR4 ignores it)")
        ->check(mc::cli::Range(1, 20));
    cmd->add_option("--fc", o->fc, "Cut-off (Hz)")->required()->check(mc::cli::PositiveNumber);
    cmd->add_option("--fs", o->fs, "Sample rate (Hz)")->required()->check(mc::cli::PositiveNumber);
    cmd->add_option("--type", o->type, "low|high|lr4-low|lr4-high")
        ->check(CLI::IsMember({"low", "high", "lr4-low", "lr4-high"}));
    mc::cli::add_output_options(*cmd, o->common);
    mc::cli::add_format_option(*cmd, o->common);
    cmd->callback([o] {
      mc::dsp::Sos sos;
      if (o->type.rfind("lr4-", 0) == 0) {
        sos = mc::dsp::linkwitz_riley(4, o->fc, o->fs, mc::dsp::parse_filter_type(o->type.substr(4)));
      } else {
        sos = mc::dsp::butter(o->order, o->fc, o->fs, mc::dsp::parse_filter_type(o->type));
      }
      nlohmann::json rows = nlohmann::json::array();
      for (const auto& s : sos) rows.push_back(s.row());
      const nlohmann::json j{{"sos", rows}};
      // One row per section, scipy's layout: b0 b1 b2 a0 a1 a2 (results.mat: also `sos`, N x 6).
      mc::CsvTable t;
      const char* names[] = {"b0", "b1", "b2", "a0", "a1", "a2"};
      for (std::size_t c = 0; c < 6; ++c) {
        std::vector<double> column;
        for (const auto& row : rows) column.push_back(row[c].get<double>());
        t.add_column(names[c], column);
      }
      mc::cli::write_result_table(o->common, "sos.csv", t, j);
      mc::cli::emit(o->common, j);
    });
  }
  {
    struct O {
      CommonOptions common;
      std::string in, column;
      WelchFlags w;
    };
    auto o = std::make_shared<O>();
    auto* cmd =
        group.add_subcommand("welch", "Welch power spectral density of one CSV column (scipy.signal.welch)");
    cmd->add_option("--in", o->in, "CSV file with a header row, or a .mat file (vector variables)")
        ->required();
    cmd->add_option("--column", o->column, "Column name")->required();
    add_welch_flags(cmd, o->w);
    mc::cli::add_output_options(*cmd, o->common);
    mc::cli::add_format_option(*cmd, o->common);
    cmd->callback([o] {
      const auto table = mc::read_columns(o->in, {o->column});
      const auto p = naming_columns(o->in, o->column, o->column, [&] {
        return mc::dsp::welch(table.column(o->column), to_options(o->w));
      });
      write_two_columns(o->common, "psd.csv", {"f_Hz", p.f_Hz}, {"psd", p.value});
    });
  }
  {
    struct O {
      CommonOptions common;
      std::string in, input, output;
      WelchFlags w;
    };
    auto o = std::make_shared<O>();
    auto* cmd = group.add_subcommand(
        "frf", "H1 frequency response and coherence; CSV f_Hz,re,im,coherence on stdout");
    cmd->add_option("--in", o->in, "CSV file with a header row, or a .mat file (vector variables)")
        ->required();
    cmd->add_option("--input", o->input, "Input column")->required();
    cmd->add_option("--output", o->output, "Output column")->required();
    add_welch_flags(cmd, o->w);
    mc::cli::add_output_options(*cmd, o->common);
    mc::cli::add_format_option(*cmd, o->common);
    cmd->callback([o] {
      const auto table = mc::read_columns(o->in, {o->input, o->output});
      const auto e = naming_columns(o->in, o->input, o->output, [&] {
        return mc::dsp::frf_h1(table.column(o->input), table.column(o->output), to_options(o->w));
      });
      std::vector<double> re(e.h.size()), im(e.h.size());
      for (std::size_t i = 0; i < e.h.size(); ++i) {
        re[i] = e.h[i].real();
        im[i] = e.h[i].imag();
      }
      mc::CsvTable t;
      t.add_column("f_Hz", e.f_Hz);
      t.add_column("re", re);
      t.add_column("im", im);
      t.add_column("coherence", e.coherence);
      mc::cli::write_result_table(o->common, "frf.csv", t, nlohmann::json::object());
      if (o->common.json) {
        mc::cli::emit(o->common, {{"f_Hz", e.f_Hz}, {"re", re}, {"im", im}, {"coherence", e.coherence}});
        return;
      }
      std::string csv = "f_Hz,re,im,coherence\n";
      for (std::size_t i = 0; i < e.h.size(); ++i) {
        csv += fmt::format("{:.17g},{:.17g},{:.17g},{:.17g}\n", e.f_Hz[i], re[i], im[i], e.coherence[i]);
      }
      std::fputs(csv.c_str(), stdout);
    });
  }
  {
    struct O {
      CommonOptions common;
      int bits = 0;
    };
    auto o = std::make_shared<O>();
    auto* cmd = group.add_subcommand("mls", "Maximum-length sequence of 0/1 (scipy.signal.max_len_seq)");
    cmd->add_option("--bits", o->bits, "Register length 2..32")->required()->check(mc::cli::Range(2, 32));
    mc::cli::add_output_options(*cmd, o->common);
    mc::cli::add_format_option(*cmd, o->common);
    cmd->callback([o] {
      if (o->bits > 24) throw mc::UsageError("--bits: at most 24 on the command line (2^24 - 1 values)");
      const auto seq = mc::dsp::max_len_seq(o->bits);
      mc::CsvTable t;
      t.add_column("seq", std::vector<double>(seq.begin(), seq.end()));
      mc::cli::write_result_table(o->common, "mls.csv", t, nlohmann::json::object());
      mc::cli::emit(o->common, {{"seq", seq}}, fmt::format("MLS of {} values", seq.size()));
    });
  }
  {
    struct O {
      CommonOptions common;
      std::string in;
      int nz = 1, np = 2;
      double fmin = 0, fmax = std::numeric_limits<double>::infinity();
    };
    auto o = std::make_shared<O>();
    auto* cmd = group.add_subcommand("tffit", "Rational transfer-function fit of an FRF CSV (f_Hz,re,im)");
    cmd->add_option("--in", o->in, "FRF CSV with columns f_Hz,re,im (or a .mat with those variables)")
        ->required();
    cmd->add_option("--nz", o->nz, "Numerator order")->check(mc::cli::Range(0, 20));
    cmd->add_option("--np", o->np, "Denominator order")->check(mc::cli::Range(1, 20));
    cmd->add_option("--fmin", o->fmin, "Band start (Hz)")->check(mc::cli::NonNegativeNumber);
    cmd->add_option("--fmax", o->fmax, "Band end (Hz)")->check(mc::cli::PositiveNumber);
    mc::cli::add_output_options(*cmd, o->common);
    mc::cli::add_format_option(*cmd, o->common);
    cmd->callback([o] {
      if (o->nz > o->np) throw mc::UsageError("--nz must not exceed --np");
      const auto table = mc::read_csv(o->in);
      mc::ident::TfFitOptions fo;
      fo.nz = o->nz;
      fo.np = o->np;
      fo.fmin_Hz = o->fmin;
      fo.fmax_Hz = o->fmax;
      std::optional<mc::ident::TfFitResult> fitted;
      mc::cli::naming_flags({{"fmin_Hz", "--fmin"}, {"fmax_Hz", "--fmax"}, {"h", o->in + ": columns re, im"}},
                            [&] { fitted = mc::ident::fit_tf(table.column("f_Hz"), read_frf(table), fo); });
      const mc::ident::TfFitResult& fit = *fitted;
      const nlohmann::json j{{"num", fit.tf.num()},
                             {"den", fit.tf.den()},
                             {"relative_rms_error", fit.relative_rms_error},
                             {"points", fit.points}};
      // tf.csv: one row per power of s, highest first; num padded with leading zeros to den's
      // length (np.polyval and scipy.signal take it as it is).
      const auto& den = fit.tf.den();
      const auto& num = fit.tf.num();
      std::vector<double> power(den.size()), padded(den.size(), 0.0);
      for (std::size_t k = 0; k < den.size(); ++k) power[k] = static_cast<double>(den.size() - 1 - k);
      std::copy(num.begin(), num.end(), padded.end() - static_cast<std::ptrdiff_t>(num.size()));
      mc::CsvTable t;
      t.add_column("power", power);
      t.add_column("num", padded);
      t.add_column("den", den);
      mc::cli::write_result_table(o->common, "tf.csv", t, j);
      mc::cli::emit(o->common, j);
    });
  }
  {
    struct O {
      CommonOptions common;
      std::string in;
      double fmin = 0, fmax = 0;
    };
    auto o = std::make_shared<O>();
    auto* cmd = group.add_subcommand("octave", "1/3-octave band averages (IEC 61260 base 10) of an FRF CSV");
    cmd->add_option("--in", o->in, "FRF CSV with columns f_Hz,re,im")->required();
    cmd->add_option("--fmin", o->fmin, "Lowest band centre (Hz), default the data's")
        ->check(mc::cli::PositiveNumber);
    cmd->add_option("--fmax", o->fmax, "Highest band centre (Hz), default the data's")
        ->check(mc::cli::PositiveNumber);
    mc::cli::add_output_options(*cmd, o->common);
    mc::cli::add_format_option(*cmd, o->common);
    cmd->callback([o] {
      const auto table = mc::read_csv(o->in);
      const auto& f = table.column("f_Hz");
      double lo = o->fmin, hi = o->fmax;
      if (lo <= 0) {
        lo = std::numeric_limits<double>::infinity();
        for (double v : f) {
          if (v > 0) lo = std::min(lo, v);
        }
      }
      if (hi <= 0) {
        for (double v : f) hi = std::max(hi, v);
      }
      // Data at DC alone (or no positive frequency) have no band to average.
      if (o->fmin <= 0 && !std::isfinite(lo))
        throw mc::InvalidInput(o->in, 0,
                               "column 'f_Hz': no positive frequency (an octave band needs one above 0 Hz)");
      if (!(hi > lo)) {
        // Name what was given: a flag, or the data's end it defaulted to.
        const std::string lo_what = o->fmin > 0 ? "--fmin" : "the data's lowest frequency";
        const std::string hi_what = o->fmax > 0 ? "--fmax" : "the data's highest frequency";
        const std::string msg =
            fmt::format("{} ({:g} Hz) must exceed {} ({:g} Hz)", hi_what, hi, lo_what, lo);
        if (o->fmin > 0 || o->fmax > 0) throw mc::UsageError(msg);
        throw mc::InvalidInput(o->in, 0, msg);
      }
      const auto b = mc::dsp::third_octave_average(f, read_frf(table), lo, hi);
      write_two_columns(o->common, "octave.csv", {"fc_Hz", b.fc_Hz}, {"mag_dB", b.mag_dB});
    });
  }
}

const bool kRegistered =
    mc::cli::register_group({"dsp", "Signal and system toolkit (filters, spectra, fits)", 20, &add_dsp});

}  // namespace
}  // namespace dsp_commands
