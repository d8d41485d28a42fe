#pragma once
/// @file
/// HTML reports with interactive plots. A Report is a list of sections, each with text, a
/// table of results and figures; write() produces one self-contained `index.html` (uPlot
/// and the page script are embedded, nothing is fetched) and, beside it, the CSV behind
/// every figure. Every module adds its figures through this one small API.

#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace mc::report {

/// `text` with < > & " as HTML entities (for text inside an element or an attribute).
std::string escape_html(std::string_view text);

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
  /// A box plot (box_plot.h, box_figure()): each series is one group of samples (y), drawn as
  /// one box at x = its position; the page gets each box's statistics from BoxStats.
  bool box = false;
};

/// A result row shown in the section's table: name, value and unit, or a text (e.g. "yes").
/// Values in m, N, s, V are shown with the SI prefix that suits them (0.569 um, not 5.69e-07 m).
struct Result {
  std::string name;
  double value;
  std::string unit;
  std::string text;  ///< shown instead of the value when set
};

/// A value for people: 4 significant digits, with the SI prefix (p, n, u, m) that puts it in
/// [1, 1000) when the unit is m, N, s, V, A or m/s and the value below 1: (5.6883e-07, "m") ->
/// {"568.8", "nm"}, (2.5e-5, "s") -> {"25", "us"}. Other units (Hz, %, "") as they are.
std::pair<std::string, std::string> human_value(double value, const std::string& unit);

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
  /// A result that is a word: "yes"/"no", a name.
  void add_text_result(std::string name, std::string text);
  /// Appends all sections of `other` (used to assemble the full report from modules).
  void append(const Report& other);

  const std::string& title() const { return title_; }
  const std::vector<Section>& sections() const { return sections_; }
  std::size_t figure_count() const;

  /// Writes DIR/index.html and DIR/fig-NN-<slug>.csv atomically; creates DIR.
  /// Throws InvalidInput if DIR cannot be written, InvalidParams for an empty or
  /// inconsistent figure (x/y of different sizes, non-finite values, log axis with values <= 0).
  std::filesystem::path write(const std::filesystem::path& dir) const;
  /// Writes the page as `page` and the figures' CSVs into `data_dir`, the page linking to each
  /// as `data_prefix` + its file name (a path relative to the page, e.g. "run-7-figures/").
  /// The CSVs are written first, the page last, each atomically. Throws as write().
  void write_page(const std::filesystem::path& page, const std::filesystem::path& data_dir,
                  const std::string& data_prefix) const;
  /// The page as a string (what write() puts in index.html); figure links get `data_prefix`.
  std::string html(const std::string& data_prefix = {}) const;

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
