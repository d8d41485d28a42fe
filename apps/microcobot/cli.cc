#include "cli.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <iostream>
#include <mutex>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "microcobot/core/error.h"
#include "microcobot/core/field_names.h"
#include "microcobot/core/input_file.h"
#include "microcobot/core/mat_file.h"
#include "signals.h"

namespace mc::cli {

namespace {
std::vector<Group>& group_registry() {
  static std::vector<Group> registry;
  return registry;
}

void check_finite(const nlohmann::json& v, const std::string& path) {
  if (v.is_number_float() && !std::isfinite(v.get<double>())) {
    throw ComputationFailed("result '" + path + "' is not a finite number");
  }
  if (v.is_object()) {
    for (auto it = v.begin(); it != v.end(); ++it)
      check_finite(it.value(), path.empty() ? it.key() : path + "." + it.key());
  } else if (v.is_array()) {
    for (std::size_t i = 0; i < v.size(); ++i) check_finite(v[i], path + "[" + std::to_string(i) + "]");
  }
}
}  // namespace

bool register_group(Group group) {
  group_registry().push_back(std::move(group));
  return true;
}

std::vector<Group> groups() {
  auto out = group_registry();
  std::stable_sort(out.begin(), out.end(), [](const Group& a, const Group& b) { return a.order < b.order; });
  return out;
}

CLI::Validator Range(double lo, double hi) {
  const std::string desc = fmt::format("[{:g} - {:g}]", lo, hi);
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(text, v)) return "'" + excerpt(text) + "' is not a number";
        if (!std::isfinite(v)) return "'" + excerpt(text) + "' is not a finite number";
        if (!(v >= lo && v <= hi)) {
          return fmt::format("{} is out of range: expected {:g} to {:g}", excerpt(text), lo, hi);
        }
        return {};
      },
      desc, "RANGE");
}

namespace {
CLI::Validator lower_bound(bool strict) {
  return CLI::Validator(
      [strict](std::string& text) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(text, v)) return "'" + excerpt(text) + "' is not a number";
        if (!std::isfinite(v)) return "'" + excerpt(text) + "' is not a finite number";
        if (strict ? !(v > 0.0) : !(v >= 0.0))
          return excerpt(text) + (strict ? " must be > 0" : " must be >= 0");
        return {};
      },
      strict ? "POSITIVE" : "NONNEGATIVE", strict ? "POSITIVE" : "NONNEGATIVE");
}
}  // namespace

const CLI::Validator PositiveNumber = lower_bound(true);
const CLI::Validator NonNegativeNumber = lower_bound(false);

void naming_flags(const std::vector<std::pair<std::string, std::string>>& field_to_flag,
                  const std::function<void()>& work) {
  naming_fields(field_to_flag, work);
}

void add_output_options(CLI::App& cmd, CommonOptions& opts) {
  cmd.add_flag("--json", opts.json, "Print a machine-readable JSON summary on stdout");
  cmd.add_option("--out", opts.out, "Write CSV artifacts and an index.html report to this directory");
}

void add_format_option(CLI::App& cmd, CommonOptions& opts) {
  auto* format =
      cmd.add_option("--format", opts.format,
                     "Format of the result data under --out: csv (default) or mat (one results.mat, MAT 5)")
          ->check(CLI::IsMember({"csv", "mat"}));
  // A format without an output directory would be silently ignored: refuse it (exit 2).
  if (CLI::Option* out = cmd.get_option_no_throw("--out")) format->needs(out);
}

namespace {

bool is_numeric_array(const nlohmann::json& j) {
  if (!j.is_array() || j.empty()) return false;
  for (const auto& x : j) {
    if (!x.is_number()) return false;
  }
  return true;
}

/// A non-empty array of numeric arrays of one length (e.g. a filter's second-order sections).
bool is_numeric_matrix(const nlohmann::json& j) {
  if (!j.is_array() || j.empty() || !is_numeric_array(j.front())) return false;
  for (const auto& row : j) {
    if (!is_numeric_array(row) || row.size() != j.front().size()) return false;
  }
  return true;
}

/// Rows of a JSON matrix as a rows x cols .mat variable (column-major).
mc::MatArray matrix(const std::string& name, const nlohmann::json& rows) {
  mc::MatArray a;
  a.name = name;
  a.rows = rows.size();
  a.cols = rows.front().size();
  a.data.resize(a.rows * a.cols);
  for (std::size_t r = 0; r < a.rows; ++r) {
    for (std::size_t c = 0; c < a.cols; ++c) a.data[r + c * a.rows] = rows[r][c].get<double>();
  }
  return a;
}

/// The numbers and numeric arrays (vectors and matrices) of a JSON summary as .mat variables
/// (key paths joined by '_').
void collect_mat(const nlohmann::json& j, const std::string& prefix, std::vector<mc::MatArray>& out) {
  for (const auto& [key, v] : j.items()) {
    std::string name = prefix.empty() ? key : prefix + "_" + key;
    for (char& c : name) {
      if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    }
    if (name.size() > 63 || !std::isalpha(static_cast<unsigned char>(name[0]))) continue;
    if (v.is_number()) {
      out.push_back(mc::MatArray::scalar(name, v.get<double>()));
    } else if (v.is_boolean()) {
      out.push_back(mc::MatArray::scalar(name, v.get<bool>() ? 1.0 : 0.0));
    } else if (is_numeric_array(v)) {
      out.push_back(mc::MatArray::column(name, v.get<std::vector<double>>()));
    } else if (is_numeric_matrix(v)) {
      out.push_back(matrix(name, v));
    } else if (v.is_object()) {
      collect_mat(v, name, out);
    }
  }
}

}  // namespace

bool write_results_mat(const CommonOptions& opts, const nlohmann::json& summary,
                       const std::vector<std::pair<std::string, std::vector<double>>>& arrays) {
  if (!opts.out || opts.format != "mat") return false;
  check_finite(summary, "");
  mc::ensure_writable_dir(*opts.out);
  std::vector<mc::MatArray> vars;
  for (const auto& [name, values] : arrays) vars.push_back(mc::MatArray::column(name, values));
  std::vector<mc::MatArray> scalars;
  collect_mat(summary, "", scalars);
  for (auto& v : scalars) {
    const bool taken =
        std::any_of(vars.begin(), vars.end(), [&](const mc::MatArray& a) { return a.name == v.name; });
    if (!taken) vars.push_back(std::move(v));
  }
  mc::write_mat(*opts.out / "results.mat", vars);
  return true;
}

void write_result_tables(const CommonOptions& opts, const std::vector<ResultTable>& tables,
                         const nlohmann::json& summary) {
  if (!opts.out) return;
  std::vector<std::pair<std::string, std::vector<double>>> columns;
  for (const auto& t : tables) {
    for (std::size_t i = 0; i < t.table.cols(); ++i) {
      columns.emplace_back(t.mat_prefix + t.table.names()[i], t.table.column(i));
    }
  }
  if (write_results_mat(opts, summary, columns)) return;
  mc::ensure_writable_dir(*opts.out);
  for (const auto& t : tables) mc::write_csv(*opts.out / t.csv_name, t.table, t.comments);
}

void write_result_table(const CommonOptions& opts, const std::string& csv_name, const mc::CsvTable& table,
                        const nlohmann::json& summary) {
  write_result_tables(opts, {{csv_name, table, "", {}}}, summary);
}

void add_params_option(CLI::App& cmd, CommonOptions& opts) {
  // No CLI11 existence check: a missing file is invalid input (exit 3), named by load_params().
  cmd.add_option("--params", opts.params, "YAML parameter file (keys as printed by 'params --json')");
}

void emit(const CommonOptions& opts, const nlohmann::json& summary, const std::string& human) {
  check_finite(summary, "");
  // Paths name the output directories, not their staging directories; while outputs are
  // staged the text waits for them to be committed (signals.h): a failed command prints no
  // summary.
  if (opts.json) {
    print_after_commit(unstaged(summary.dump()) + "\n");
  } else if (!human.empty()) {
    print_after_commit(unstaged(human) + (human.back() == '\n' ? "" : "\n"));
  } else {
    print_after_commit(unstaged(summary.dump(2)) + "\n");
  }
}

void write_report_if_requested(const CommonOptions& opts, const report::Report& report) {
  if (!opts.out) return;
  const auto path = report.write(*opts.out);
  spdlog::info("report written to {}", unstaged(path.string()));
}

void progress(const std::string& task, std::size_t done, std::size_t total) {
  static std::mutex mutex;
  const std::lock_guard<std::mutex> lock(mutex);
  if (spdlog::get_level() > spdlog::level::info) return;
  std::cerr << "\r" << task << ": " << done << "/" << total << (done >= total ? "\n" : "") << std::flush;
}

}  // namespace mc::cli
