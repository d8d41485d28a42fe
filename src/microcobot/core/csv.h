#pragma once
/// @file
/// Numeric CSV tables: a header row of unit-suffixed names (`t_s,u_V,x2_m`), `#` comment
/// lines, then rows of finite doubles. Reading rejects text cells, NaN/Inf, ragged rows and
/// empty files with "file:line: what". Writing is atomic (temporary file, then rename).

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace mc {

/// A column-major table of doubles with named columns.
class CsvTable {
 public:
  CsvTable() = default;
  explicit CsvTable(std::vector<std::string> names);

  /// Adds a column; all columns must have the same length when written.
  void add_column(std::string name, std::vector<double> values);
  /// Appends one row (values in column order); throws std::invalid_argument on size mismatch.
  void add_row(std::span<const double> values);

  std::size_t rows() const { return columns_.empty() ? 0 : columns_.front().size(); }
  std::size_t cols() const { return names_.size(); }
  const std::vector<std::string>& names() const { return names_; }
  bool has(const std::string& name) const;
  /// The column `name`; throws InvalidInput "<source>: missing column 'name' (have: ...)".
  const std::vector<double>& column(const std::string& name) const;
  const std::vector<double>& column(std::size_t index) const { return columns_.at(index); }
  /// Where the table was read from (for error messages); empty for tables built in memory.
  const std::string& source() const { return source_; }
  void set_source(std::string source) { source_ = std::move(source); }

 private:
  std::vector<std::string> names_;
  std::vector<std::vector<double>> columns_;
  std::string source_;
};

/// Reads a CSV file. Throws InvalidInput naming the file and line on any defect.
CsvTable read_csv(const std::filesystem::path& file);
/// Parses CSV text; `source` names it in error messages.
CsvTable parse_csv(const std::string& text, const std::string& source);

/// Writes `table` to `file` atomically; `comment` lines (without '#') go above the header.
/// Throws InvalidInput if the directory is not writable or columns differ in length.
void write_csv(const std::filesystem::path& file, const CsvTable& table,
               const std::vector<std::string>& comment = {});

/// Writes `text` to `file` atomically: a temporary file in the same directory, flushed, then
/// renamed over the target, so a reader never sees a partial file. Throws InvalidInput.
void write_file_atomic(const std::filesystem::path& file, const std::string& text);

/// Creates `dir` (and parents) or throws InvalidInput if it cannot be created or written.
void ensure_writable_dir(const std::filesystem::path& dir);

}  // namespace mc
