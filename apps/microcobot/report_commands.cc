// `microcobot report`: the full report, every module's part in the architecture's order.

#include <algorithm>

#include <spdlog/spdlog.h>

#include "cli.h"
#include "microcobot/core/error.h"
#include "microcobot/report/report.h"
#include "signals.h"

namespace report_commands {
namespace {

struct ReportOptions {
  mc::cli::CommonOptions common;
  std::vector<std::string> only;
};

void run_report(const ReportOptions& opts) {
  mc::report::Report full("microcobot report");
  std::size_t done = 0;
  const auto parts = mc::cli::report_parts();
  for (const auto& name : opts.only) {
    if (std::none_of(parts.begin(), parts.end(), [&](const auto& p) { return p.name == name; })) {
      std::string known;
      for (const auto& p : parts) known += (known.empty() ? "" : ", ") + p.name;
      throw mc::UsageError("unknown report part '" + name + "' (known: " + known + ")");
    }
  }
  std::vector<std::string> built;
  for (const auto& part : parts) {
    if (!opts.only.empty() && std::find(opts.only.begin(), opts.only.end(), part.name) == opts.only.end()) {
      continue;
    }
    mc::report::Report piece(part.name);
    part.build(piece);
    full.append(piece);
    built.push_back(part.name);
    mc::cli::progress("report", ++done, opts.only.empty() ? parts.size() : opts.only.size());
  }
  const auto dir = opts.common.out ? *opts.common.out : mc::cli::stage_output("out/report");
  const auto path = full.write(dir);
  nlohmann::json summary{{"index", path.string()}, {"parts", built}, {"figures", full.figure_count()}};
  mc::cli::emit(opts.common, summary, "report written to " + path.string());
}

void add_report(CLI::App& cmd) {
  auto opts = std::make_shared<ReportOptions>();
  cmd.add_flag("--json", opts->common.json, "Print a machine-readable JSON summary on stdout");
  cmd.add_option("--out", opts->common.out, "Directory of the report (default out/report)");
  cmd.add_option("--only", opts->only, "Build only these parts (by name)");
  cmd.callback([opts] { run_report(*opts); });
}

const bool kRegistered = mc::cli::register_group(
    {"report", "Build the full HTML report (every module's figures) into --out DIR", 100, &add_report});

}  // namespace
}  // namespace report_commands

// The generator every simulation draws its noise from, checked against the density it
// promises: a histogram of 200 000 draws over the standard normal density.
#include <cmath>
#include "microcobot/core/rng.h"
namespace report_commands {
namespace {
void rng_part(mc::report::Report& r) {
  r.section("Random number generator",
            "Sensor noise, PRBS seeds and Brownian motion all come from mc::Rng "
            "(xoshiro256**, identical streams on every platform). Histogram of 200000 normal "
            "draws (seed 1) against the standard normal density.");
  mc::Rng rng(1);
  constexpr int kBins = 81;
  constexpr double kLo = -4.05, kWidth = 0.1;
  constexpr int kDraws = 200000;
  std::vector<double> count(kBins, 0.0), centre(kBins), density(kBins);
  double sum = 0, sum2 = 0;
  for (int i = 0; i < kDraws; ++i) {
    const double v = rng.normal();
    sum += v;
    sum2 += v * v;
    const int b = static_cast<int>(std::floor((v - kLo) / kWidth));
    if (b >= 0 && b < kBins) count[static_cast<std::size_t>(b)] += 1.0;
  }
  for (int b = 0; b < kBins; ++b) {
    const auto i = static_cast<std::size_t>(b);
    centre[i] = kLo + (b + 0.5) * kWidth;
    count[i] /= kDraws * kWidth;
    density[i] = std::exp(-0.5 * centre[i] * centre[i]) / std::sqrt(2 * M_PI);
  }
  const double mean = sum / kDraws;
  r.add_result("mean of draws", mean);
  r.add_result("variance of draws", sum2 / kDraws - mean * mean);
  r.add_figure({"Normal draws",
                "Histogram (points) against the N(0,1) density (line).",
                {"Value", "", false},
                {"Probability density", "", false},
                {{"histogram", centre, count, true}, {"N(0,1) density", centre, density, false}}});
}
const bool kRngPart = mc::cli::register_report_part({"rng", 5, &rng_part});
}  // namespace
}  // namespace report_commands
