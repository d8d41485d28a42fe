#include "microcobot/report/report.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/report/assets.h"
#include "microcobot/report/box_plot.h"

namespace mc::report {

namespace {

// Browsers draw at most a few thousand pixels across: larger series are reduced to their
// per-bucket minimum and maximum, which keeps every peak visible. The CSV keeps everything.
constexpr std::size_t kMaxPlotPoints = 8000;

void reduce_for_plot(const Series& s, std::vector<double>& x, std::vector<double>& y) {
  const std::size_t n = s.x.size();
  if (n <= kMaxPlotPoints) {
    x = s.x;
    y = s.y;
    return;
  }
  const std::size_t buckets = kMaxPlotPoints / 2;
  x.clear();
  y.clear();
  for (std::size_t b = 0; b < buckets; ++b) {
    const std::size_t i0 = b * n / buckets, i1 = std::max(i0 + 1, (b + 1) * n / buckets);
    std::size_t imin = i0, imax = i0;
    for (std::size_t i = i0; i < i1; ++i) {
      if (s.y[i] < s.y[imin]) imin = i;
      if (s.y[i] > s.y[imax]) imax = i;
    }
    for (std::size_t i : {std::min(imin, imax), std::max(imin, imax)}) {
      x.push_back(s.x[i]);
      y.push_back(s.y[i]);
    }
  }
}

std::string axis_column(const Axis& a) {
  std::string s = slug(a.label);
  std::replace(s.begin(), s.end(), '-', '_');
  return a.unit.empty() ? s : s + "_" + a.unit;
}

// JSON inside <script>: "</" must not appear.
std::string script_safe(std::string json) {
  std::size_t pos = 0;
  while ((pos = json.find("</", pos)) != std::string::npos) {
    json.replace(pos, 2, "<\\/");
    pos += 3;
  }
  return json;
}

std::string figure_file(std::size_t index, const Figure& f) {
  return fmt::format("fig-{:02d}-{}.csv", index, slug(f.title));
}

}  // namespace

std::string escape_html(std::string_view s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string slug(const std::string& title) {
  std::string out;
  for (char c : title) {
    if (std::isalnum(static_cast<unsigned char>(c))) {
      out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    } else if (!out.empty() && out.back() != '-') {
      out += '-';
    }
  }
  while (!out.empty() && out.back() == '-') out.pop_back();
  return out.empty() ? "figure" : out.substr(0, 48);
}

void validate_figure(const Figure& f) {
  const std::string where = "figure '" + f.title + "'";
  require(!f.series.empty(), where, "has no series");
  require(!f.box || (!f.x.log && !f.y.log), where, "is a box plot: its axes are linear");
  for (const auto& s : f.series) {
    const std::string w = where + " series '" + s.name + "'";
    require(!s.x.empty(), w, "is empty");
    require(s.x.size() == s.y.size(), w, fmt::format("x has {} values, y has {}", s.x.size(), s.y.size()));
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      require(std::isfinite(s.x[i]) && std::isfinite(s.y[i]), w,
              fmt::format("non-finite value at index {}", i));
      require(!f.x.log || s.x[i] > 0, w, fmt::format("x <= 0 on a log axis at index {}", i));
      require(!f.y.log || s.y[i] > 0, w, fmt::format("y <= 0 on a log axis at index {}", i));
    }
  }
}

Report::Report(std::string title) : title_(std::move(title)) {}

Section& Report::section(std::string title, std::string text) {
  sections_.push_back(Section{std::move(title), std::move(text), {}, {}});
  return sections_.back();
}

Section& Report::current() {
  if (sections_.empty()) section(title_);
  return sections_.back();
}

void Report::add_figure(Figure figure) { current().figures.push_back(std::move(figure)); }

void Report::add_result(std::string name, double value, std::string unit) {
  current().results.push_back(Result{std::move(name), value, std::move(unit), {}});
}

void Report::add_text_result(std::string name, std::string text) {
  current().results.push_back(Result{std::move(name), 0.0, {}, std::move(text)});
}

std::pair<std::string, std::string> human_value(double value, const std::string& unit) {
  static const char* const kScaled[] = {"m", "N", "s", "V", "A", "m/s"};
  const bool scaled = std::find(std::begin(kScaled), std::end(kScaled), unit) != std::end(kScaled);
  const double a = std::abs(value);
  if (!scaled || !std::isfinite(value) || a == 0.0 || a >= 1.0) return {fmt::format("{:.4g}", value), unit};
  struct Prefix {
    double scale;
    const char* name;
  };
  static constexpr Prefix kPrefixes[] = {{1e-3, "m"}, {1e-6, "u"}, {1e-9, "n"}, {1e-12, "p"}};
  for (const auto& p : kPrefixes) {
    // 0.99996 mm would print as "1000 um": it goes to the larger unit once rounded.
    if (std::stod(fmt::format("{:.4g}", a / p.scale)) >= 1.0)
      return {fmt::format("{:.4g}", value / p.scale), p.name + unit};
  }
  return {fmt::format("{:.4g}", value / 1e-12), "p" + unit};
}

void Report::append(const Report& other) {
  sections_.insert(sections_.end(), other.sections_.begin(), other.sections_.end());
}

std::size_t Report::figure_count() const {
  std::size_t n = 0;
  for (const auto& s : sections_) n += s.figures.size();
  return n;
}

std::string Report::html(const std::string& data_prefix) const {
  nlohmann::json doc;
  doc["title"] = title_;
  doc["sections"] = nlohmann::json::array();
  std::size_t index = 0;
  for (const auto& sec : sections_) {
    nlohmann::json js;
    js["title"] = sec.title;
    js["text"] = sec.text;
    js["results"] = nlohmann::json::array();
    for (const auto& r : sec.results) {
      const auto [value, unit] = r.text.empty() ? human_value(r.value, r.unit) : std::pair{r.text, r.unit};
      js["results"].push_back({{"name", r.name}, {"value", value}, {"unit", unit}});
    }
    js["figures"] = nlohmann::json::array();
    for (const auto& f : sec.figures) {
      validate_figure(f);
      ++index;
      nlohmann::json jf;
      jf["id"] = fmt::format("fig-{:02d}", index);
      jf["csv"] = data_prefix + figure_file(index, f);
      jf["title"] = f.title;
      jf["caption"] = f.caption;
      jf["x"] = {{"label", f.x.label}, {"unit", f.x.unit}, {"log", f.x.log}};
      jf["y"] = {{"label", f.y.label}, {"unit", f.y.unit}, {"log", f.y.log}};
      jf["series"] = nlohmann::json::array();
      for (const auto& s : f.series) {
        std::vector<double> x, y;
        reduce_for_plot(s, x, y);
        jf["series"].push_back({{"name", s.name}, {"x", x}, {"y", y}, {"points", s.points}});
        if (f.box) {
          const BoxStats b = box_stats(s.y);  // every sample, not the reduced ones
          jf["series"].back()["box"] = {{"n", b.n},
                                        {"q1", b.q1},
                                        {"median", b.median},
                                        {"q3", b.q3},
                                        {"low", b.whisker_low},
                                        {"high", b.whisker_high},
                                        {"outliers", b.outliers}};
        }
      }
      jf["box"] = f.box;
      js["figures"].push_back(std::move(jf));
    }
    doc["sections"].push_back(std::move(js));
  }

  std::string page;
  page += "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n";
  page += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  page += "<title>" + escape_html(title_) + "</title>\n<style>\n";
  page += reinterpret_cast<const char*>(assets::kUplotCss);
  page += "\n";
  page += reinterpret_cast<const char*>(assets::kReportCss);
  page += "\n</style>\n</head><body>\n<div id=\"report\"></div>\n";
  page += "<script type=\"application/json\" id=\"report-data\">";
  page += script_safe(doc.dump());
  page += "</script>\n<script>\n";
  page += reinterpret_cast<const char*>(assets::kUplotJs);
  page += "\n</script>\n<script>\n";
  page += reinterpret_cast<const char*>(assets::kReportJs);
  page += "\n</script>\n</body></html>\n";
  return page;
}

std::filesystem::path Report::write(const std::filesystem::path& dir) const {
  write_page(dir / "index.html", dir, "");
  return dir / "index.html";
}

void Report::write_page(const std::filesystem::path& page_path, const std::filesystem::path& dir,
                        const std::string& data_prefix) const {
  const std::string page = html(data_prefix);  // validates every figure before anything is written
  if (!page_path.parent_path().empty()) ensure_writable_dir(page_path.parent_path());
  ensure_writable_dir(dir);
  std::size_t index = 0;
  for (const auto& sec : sections_) {
    for (const auto& f : sec.figures) {
      ++index;
      CsvTable table;
      const bool shared_x = std::all_of(f.series.begin(), f.series.end(),
                                        [&](const Series& s) { return s.x == f.series.front().x; });
      if (shared_x) {
        table.add_column(axis_column(f.x), f.series.front().x);
        for (std::size_t i = 0; i < f.series.size(); ++i) {
          std::string name = slug(f.series[i].name);
          std::replace(name.begin(), name.end(), '-', '_');
          if (table.has(name)) name += fmt::format("_{}", i + 1);
          table.add_column(name, f.series[i].y);
        }
      } else {
        std::vector<double> id, x, y;
        for (std::size_t i = 0; i < f.series.size(); ++i) {
          id.insert(id.end(), f.series[i].x.size(), static_cast<double>(i + 1));
          x.insert(x.end(), f.series[i].x.begin(), f.series[i].x.end());
          y.insert(y.end(), f.series[i].y.begin(), f.series[i].y.end());
        }
        table.add_column("series", id);
        table.add_column(axis_column(f.x), x);
        table.add_column(axis_column(f.y), y);
      }
      std::vector<std::string> comment{f.title};
      for (std::size_t i = 0; i < f.series.size(); ++i) {
        comment.push_back(fmt::format("series {}: {}", i + 1, f.series[i].name));
      }
      write_csv(dir / figure_file(index, f), table, comment);
    }
  }
  write_file_atomic(page_path, page);
}

}  // namespace mc::report
