#include "microcobot/core/csv.h"

#include <unistd.h>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <unordered_set>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "microcobot/core/staged_file.h"

namespace mc {

CsvTable::CsvTable(std::vector<std::string> names) : names_(std::move(names)), columns_(names_.size()) {}

void CsvTable::add_column(std::string name, std::vector<double> values) {
  names_.push_back(std::move(name));
  columns_.push_back(std::move(values));
}

void CsvTable::add_row(std::span<const double> values) {
  if (values.size() != names_.size()) {
    throw std::invalid_argument(
        fmt::format("CsvTable::add_row: {} values for {} columns", values.size(), names_.size()));
  }
  for (std::size_t i = 0; i < values.size(); ++i) columns_[i].push_back(values[i]);
}

bool CsvTable::has(const std::string& name) const {
  for (const auto& n : names_) {
    if (n == name) return true;
  }
  return false;
}

const std::vector<double>& CsvTable::column(const std::string& name) const {
  for (std::size_t i = 0; i < names_.size(); ++i) {
    if (names_[i] == name) return columns_[i];
  }
  std::string have;
  for (const auto& n : names_) {
    have += (have.empty() ? "" : ",") + n;
    if (have.size() > 80) break;
  }
  throw InvalidInput(source_, 0, fmt::format("missing column '{}' (have: {})", excerpt(name), excerpt(have)));
}

namespace {

std::string trim(std::string_view s) {
  std::size_t b = 0, e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\t' || s[b] == '\r')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t' || s[e - 1] == '\r')) --e;
  return std::string(s.substr(b, e - b));
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    cells.push_back(trim(std::string_view(line).substr(start, comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return cells;
}

}  // namespace

namespace {

// Text with its line endings made '\n': a UTF-8 byte-order mark is dropped, CRLF and lone CR
// (old Mac files) end lines like LF.
std::string normalized(const std::string& raw) {
  std::string_view text(raw);
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\r') {
      out += '\n';
      if (i + 1 < text.size() && text[i + 1] == '\n') ++i;
    } else {
      out += text[i];
    }
  }
  return out;
}

}  // namespace

CsvTable parse_csv(const std::string& raw, const std::string& source) {
  std::istringstream in(normalized(raw));
  std::string line;
  std::size_t line_no = 0;
  CsvTable table;
  bool have_header = false;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string t = trim(line);
    if (t.empty() || t[0] == '#') continue;
    std::vector<std::string> cells = split(t);
    if (!have_header) {
      std::unordered_set<std::string_view> seen;  // linear in the header's width
      seen.reserve(cells.size());
      for (std::size_t i = 0; i < cells.size(); ++i) {
        if (cells[i].empty()) {
          throw InvalidInput(source, line_no, fmt::format("empty column name in header (column {})", i + 1));
        }
        if (!seen.insert(cells[i]).second) {
          throw InvalidInput(source, line_no, fmt::format("duplicate column '{}'", excerpt(cells[i])));
        }
      }
      table = CsvTable(cells);
      table.set_source(source);
      have_header = true;
      continue;
    }
    if (cells.size() != table.cols()) {
      throw InvalidInput(source, line_no,
                         fmt::format("row has {} cells, header has {}", cells.size(), table.cols()));
    }
    std::vector<double> row(cells.size());
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const std::string& c = cells[i];
      double v = 0.0;
      const char* first = c.data();
      const char* last = c.data() + c.size();
      if (!c.empty() && *first == '+') ++first;
      const auto [ptr, ec] = std::from_chars(first, last, v);
      if (c.empty() || ec != std::errc() || ptr != last) {
        throw InvalidInput(
            source, line_no,
            fmt::format("column '{}': '{}' is not a number", excerpt(table.names()[i]), excerpt(c)));
      }
      if (!std::isfinite(v)) {
        throw InvalidInput(
            source, line_no,
            fmt::format("column '{}': non-finite value '{}'", excerpt(table.names()[i]), excerpt(c)));
      }
      row[i] = v;
    }
    table.add_row(row);
  }
  if (!have_header) throw InvalidInput(source, 0, "empty file (no header row)");
  if (table.rows() == 0) throw InvalidInput(source, 0, "no data rows");
  return table;
}

CsvTable read_csv(const std::filesystem::path& file) {
  return parse_csv(read_input_file(file, kMaxCsvFileBytes, "CSV file"), file.string());
}

void ensure_writable_dir(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) {
    throw InvalidInput(dir.string(), 0, "cannot create output directory: " + ec.message());
  }
  if (::access(dir.c_str(), W_OK) != 0) {
    throw InvalidInput(dir.string(), 0, "output directory is not writable");
  }
}

void write_file_atomic(const std::filesystem::path& file, const std::string& text) {
  StagedFile f(file);
  f.write(text);
  f.commit();
}

void write_csv(const std::filesystem::path& file, const CsvTable& table,
               const std::vector<std::string>& comment) {
  for (std::size_t i = 0; i < table.cols(); ++i) {
    if (table.column(i).size() != table.rows()) {
      throw InvalidInput(file.string(), 0,
                         fmt::format("column '{}' has {} rows, expected {}", table.names()[i],
                                     table.column(i).size(), table.rows()));
    }
  }
  std::string out;
  out.reserve(table.rows() * table.cols() * 14 + 256);
  for (const auto& c : comment) out += "# " + c + "\n";
  for (std::size_t i = 0; i < table.cols(); ++i) out += (i ? "," : "") + table.names()[i];
  out += '\n';
  char buf[32];
  for (std::size_t r = 0; r < table.rows(); ++r) {
    for (std::size_t c = 0; c < table.cols(); ++c) {
      if (c) out += ',';
      const double v = table.column(c)[r];
      if (!std::isfinite(v)) {
        throw ComputationFailed(fmt::format("{}: non-finite value in column '{}' at row {}", file.string(),
                                            table.names()[c], r + 1));
      }
      const auto res = std::to_chars(buf, buf + sizeof buf, v);  // shortest round-trip form
      out.append(buf, res.ptr);
    }
    out += '\n';
  }
  write_file_atomic(file, out);
}

}  // namespace mc
