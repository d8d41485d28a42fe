// `microcobot report`: the full report, every module's part in the architecture's order.

#include <algorithm>

#include <spdlog/spdlog.h>

#include "cli.h"
#include "microcobot/core/error.h"
#include "microcobot/report/report.h"
#include "microcobot/studies/report_parts.h"
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
  const auto parts = mc::studies::report_parts();
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
