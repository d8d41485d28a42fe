#pragma once
/// @file
/// The command registry of the `microcobot` CLI. Each command group lives in its own file
/// and registers itself at static-initialisation time:
/// @code
///   namespace {
///   void add_dsp(CLI::App& group) { ... group.add_subcommand("butter", ...) ... }
///   const bool kRegistered = mc::cli::register_group({"dsp", "Signal and system toolkit", 20, &add_dsp});
///   }
/// @endcode
/// Conventions every command follows (docs/architecture.md): `--json` prints one JSON object on stdout
/// and nothing else there; `--out DIR` writes CSV artifacts (and an index.html report);
/// `--params FILE.yaml` takes the keys `<group> params --json` prints. Errors are thrown as
/// mc::Error subclasses and turned into one line on stderr and the exit code by main.cc.

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "microcobot/core/csv.h"
#include "microcobot/report/report.h"

namespace mc::cli {

struct Group {
  std::string name;
  std::string description;
  int order;  ///< position in --help (the architecture's order, bottom-up)
  std::function<void(CLI::App&)> add;
};

/// Registers a command group; returns true (for a static initialiser).
bool register_group(Group group);
/// All registered groups, sorted by order.
std::vector<Group> groups();

/// CLI11's Range with the bounds in `%g` style ("1e-09 to 0.0001", not "0.000000 to
/// 0.000100") and NaN refused; the message names the flag (CLI11 prefixes it).
CLI::Validator Range(double lo, double hi);
/// CLI11's PositiveNumber / NonNegativeNumber without their DBL_MAX bound in the message.
extern const CLI::Validator PositiveNumber;
extern const CLI::Validator NonNegativeNumber;

/// Runs `work`; an InvalidParams about a parameter the user set by a flag is re-thrown (exit 3)
/// with each field named in `field_to_flag` replaced by its flag ({"lead_m", "--lead"}): the
/// message blames what the user typed, not the library's name for it.
void naming_flags(const std::vector<std::pair<std::string, std::string>>& field_to_flag,
                  const std::function<void()>& work);

/// Options every command shares.
struct CommonOptions {
  bool json = false;
  std::optional<std::filesystem::path> out;
  std::optional<std::filesystem::path> params;
  std::string format = "csv";  ///< --format: "csv" (CSV files) or "mat" (one results.mat)
};

/// Adds `--json` and `--out DIR` to `cmd`.
void add_output_options(CLI::App& cmd, CommonOptions& opts);
/// Adds `--format csv|mat` to `cmd` (commands whose --out holds result data).
void add_format_option(CLI::App& cmd, CommonOptions& opts);
/// With --out and --format mat: writes DIR/results.mat (MAT 5, docs/cli.md) holding `arrays` and
/// every number and numeric array of `summary`, named by its key path joined by '_'
/// (e.g. mode_a_frequency_Hz). Returns true when it wrote the file.
bool write_results_mat(const CommonOptions& opts, const nlohmann::json& summary,
                       const std::vector<std::pair<std::string, std::vector<double>>>& arrays = {});
/// The result table under --out: DIR/`csv_name` (CSV, the default), or with --format mat
/// DIR/results.mat holding the table's columns (by their CSV names) and the summary's numbers as
/// write_results_mat() does. Nothing without --out.
void write_result_table(const CommonOptions& opts, const std::string& csv_name, const mc::CsvTable& table,
                        const nlohmann::json& summary);
/// One result table under --out: DIR/`csv_name` (with `comments` as '#' lines), or with
/// --format mat its columns in results.mat, named `mat_prefix` + the column's name.
struct ResultTable {
  std::string csv_name;
  const mc::CsvTable& table;
  std::string mat_prefix;
  std::vector<std::string> comments;
};
/// Several result tables: each to its CSV file, or all of them and the summary's numbers to one
/// results.mat (write_results_mat()). Nothing without --out.
void write_result_tables(const CommonOptions& opts, const std::vector<ResultTable>& tables,
                         const nlohmann::json& summary);
/// Adds `--params FILE` to `cmd`.
void add_params_option(CLI::App& cmd, CommonOptions& opts);

/// Prints `summary` as JSON on stdout when --json, else `human` (or an indented form of the
/// summary when `human` is empty). Throws ComputationFailed if the summary holds NaN/Inf.
void emit(const CommonOptions& opts, const nlohmann::json& summary, const std::string& human = {});

/// Writes `report` to opts.out (if given) and logs where it went.
void write_report_if_requested(const CommonOptions& opts, const report::Report& report);

/// Progress on stderr for long work (quiet with --json unless -v). Thread-safe.
void progress(const std::string& task, std::size_t done, std::size_t total);

}  // namespace mc::cli
