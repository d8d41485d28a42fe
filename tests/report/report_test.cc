#include "microcobot/report/report.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "support/test_support.h"

namespace mc::report {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

Figure bode() {
  return {"Bode magnitude", "A first-order low-pass.", {"Frequency", "Hz", true}, {"Magnitude", "dB", false},
          {{"H(f)", {1, 10, 100, 1000}, {0, -0.04, -3, -20}, false}}};
}

TEST(Report, WritesSelfContainedHtmlAndOneCsvPerFigure) {
  test::TempDir dir;
  Report r("Test report");
  r.section("Filters", "Paragraph one.\n\nParagraph two.");
  r.add_result("cut-off", 100.0, "Hz");
  r.add_figure(bode());
  r.section("Loops");
  r.add_figure({"Hysteresis", "", {"Voltage", "V", false}, {"Position", "m", false},
                {{"up", {0, 1, 2}, {0, 1, 3}, false}, {"down", {2, 1, 0}, {3, 2, 0}, false}}});
  const auto index = r.write(dir.path());
  EXPECT_EQ(index, dir / "index.html");
  const std::string html = test::read_text(index);
  EXPECT_THAT(html, HasSubstr("uPlot"));           // the library is inlined
  EXPECT_THAT(html, Not(HasSubstr("src=\"http")));  // nothing is fetched
  EXPECT_THAT(html, Not(HasSubstr("<script src")));
  EXPECT_THAT(html, HasSubstr("Bode magnitude"));

  const auto a = read_csv(dir / "fig-01-bode-magnitude.csv");
  EXPECT_EQ(a.names(), (std::vector<std::string>{"frequency_Hz", "h_f"}));
  EXPECT_DOUBLE_EQ(a.column("h_f")[2], -3.0);
  const auto b = read_csv(dir / "fig-02-hysteresis.csv");  // series with their own x: long format
  EXPECT_EQ(b.names(), (std::vector<std::string>{"series", "voltage_V", "position_m"}));
  EXPECT_EQ(b.rows(), 6u);
}

TEST(Report, ScriptClosingTagsInTextCannotBreakThePage) {
  Report r("</script><script>alert(1)</script>");
  r.section("x", "</script>");
  r.add_figure(bode());
  const std::string html = r.html();
  const auto data = html.find("id=\"report-data\">");
  const auto end = html.find("</script>", data);
  EXPECT_EQ(html.substr(data, end - data).find("</"), std::string::npos);
}

TEST(Report, LargeSeriesAreReducedForThePlotButNotForTheCsv) {
  test::TempDir dir;
  Report r("big");
  std::vector<double> x(100000), y(100000);
  for (std::size_t i = 0; i < x.size(); ++i) {
    x[i] = static_cast<double>(i);
    y[i] = (i == 54321) ? 10.0 : 0.0;  // a single-sample spike must survive the reduction
  }
  r.add_figure({"Spike", "", {"Sample", "", false}, {"Value", "", false}, {{"y", x, y, false}}});
  r.write(dir.path());
  EXPECT_EQ(read_csv(dir / "fig-01-spike.csv").rows(), 100000u);
  const std::string html = test::read_text(dir / "index.html");
  EXPECT_LT(html.size(), 600000u);
  EXPECT_THAT(html, HasSubstr("54321"));
}

TEST(Report, InconsistentFiguresAreRejectedBeforeAnythingIsWritten) {
  test::TempDir dir;
  auto check = [&](Figure f, const std::string& message) {
    Report r("bad");
    r.add_figure(std::move(f));
    try {
      r.write(dir.path());
      ADD_FAILURE() << message;
    } catch (const InvalidParams& e) {
      EXPECT_THAT(e.what(), HasSubstr(message));
    }
    EXPECT_FALSE(std::filesystem::exists(dir / "index.html"));
  };
  Figure f = bode();
  f.series[0].y.pop_back();
  check(f, "x has 4 values, y has 3");
  f = bode();
  f.series[0].x[0] = 0.0;
  check(f, "x <= 0 on a log axis at index 0");
  f = bode();
  f.series[0].y[1] = std::nan("");
  check(f, "non-finite value at index 1");
  f = bode();
  f.series.clear();
  check(f, "has no series");
}

TEST(Report, UnwritableDirectoryIsInvalidInput) {
  test::TempDir dir;
  test::write_text(dir / "file", "x");
  Report r("x");
  r.add_figure(bode());
  EXPECT_THROW(r.write(dir / "file" / "sub"), InvalidInput);
}

TEST(Report, SlugsAreFileNameSafe) {
  EXPECT_EQ(slug("Fig. 3.13: LR4 + HF (combined)"), "fig-3-13-lr4-hf-combined");
  EXPECT_EQ(slug("***"), "figure");
}

}  // namespace
}  // namespace mc::report
