#pragma once
/// @file
/// HTML reports with interactive plots. A Report is a list of sections, each with text, a
/// table of results and figures; write() produces one self-contained `index.html` (uPlot
/// and the page script are embedded, nothing is fetched) and, beside it, the CSV behind
/// every figure. Every module adds its figures through this one small API.

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace mc::report {

/// One axis: a label with its unit, and its scale.
struct Axis {
  std::string label;  ///< e.g. "Frequency"
  std::string unit;   ///< SI unit, e.g. "Hz"; empty for dimensionless
  bool log = false;   ///< logarithmic scale (all values must then be > 0)
};

/// A named curve. Series of one figure may have different x values (e.g. hysteresis loops).
struct Series {
  std::string name;
  std::vector<double> x;
  std::vector<double> y;
  bool points = false;  ///< draw markers instead of a line
};

struct Figure {
  std::string title;
  std::string caption;
  Axis x;
  Axis y;
  std::vector<Series> series;
};

/// A result row shown in the section's table: name, value and unit.
struct Result {
  std::string name;
  double value;
  std::string unit;
};

struct Section {
  std::string title;
  std::string text;  ///< plain text paragraphs, separated by blank lines
  std::vector<Result> results;
  std::vector<Figure> figures;
};

class Report {
 public:
  explicit Report(std::string title);

  /// Starts a new section; later add_*() calls go into it.
  Section& section(std::string title, std::string text = {});
  void add_figure(Figure figure);
  void add_result(std::string name, double value, std::string unit = {});
  /// Appends all sections of `other` (used to assemble the full report from modules).
  void append(const Report& other);

  const std::string& title() const { return title_; }
  const std::vector<Section>& sections() const { return sections_; }
  std::size_t figure_count() const;

  /// Writes DIR/index.html and DIR/fig-NN-<slug>.csv atomically; creates DIR.
  /// Throws InvalidInput if DIR cannot be written, InvalidParams for an empty or
  /// inconsistent figure (x/y of different sizes, non-finite values, log axis with values <= 0).
  std::filesystem::path write(const std::filesystem::path& dir) const;
  /// The page as a string (what write() puts in index.html).
  std::string html() const;

 private:
  Section& current();
  std::string title_;
  std::vector<Section> sections_;
};

/// Checks a figure's consistency (see Report::write); throws InvalidParams naming the series.
void validate_figure(const Figure& figure);

/// File-name slug of a title: lower case, [a-z0-9-].
std::string slug(const std::string& title);

}  // namespace mc::report
