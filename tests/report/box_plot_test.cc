#include "microcobot/report/box_plot.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <nlohmann/json.hpp>

#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "support/test_support.h"

namespace mc::report {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

TEST(BoxPlot, TukeysBoxWithQuartilesAsNumpyAndOutliersBeyondOneAndAHalfIqr) {
  // numpy.percentile([1..10, 100], [25, 50, 75]) = 3.5, 6, 8.5: IQR 5, fences -4 and 16.
  const BoxStats b = box_stats({100, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1});
  EXPECT_EQ(b.n, 11u);
  EXPECT_DOUBLE_EQ(b.q1, 3.5);
  EXPECT_DOUBLE_EQ(b.median, 6.0);
  EXPECT_DOUBLE_EQ(b.q3, 8.5);
  EXPECT_DOUBLE_EQ(b.whisker_low, 1.0);  // the furthest samples within the fences, not the fences
  EXPECT_DOUBLE_EQ(b.whisker_high, 10.0);
  EXPECT_THAT(b.outliers, ElementsAre(100.0));
  const BoxStats one = box_stats({2.5});
  EXPECT_EQ(one.median, 2.5);
  EXPECT_EQ(one.whisker_low, 2.5);
  EXPECT_TRUE(one.outliers.empty());
  EXPECT_THROW(box_stats({}), InvalidParams);
  EXPECT_THROW(box_stats({1.0, std::numeric_limits<double>::quiet_NaN()}), InvalidParams);
}

TEST(BoxPlot, TheFigureCarriesEachGroupsStatisticsToThePageAndEverySampleToItsCsv) {
  test::TempDir dir;
  Report r("boxes");
  r.add_figure(box_figure("Cycle time by mode", "", "Mode", {"Cycle time", "s"},
                          {{"auto", {20, 21, 22, 60}}, {"manual", {50, 55}}}));
  r.write(dir.path());
  const std::string html = test::read_text(dir / "index.html");
  const auto from = html.find("id=\"report-data\">") + 17;
  const auto doc = nlohmann::json::parse(html.substr(from, html.find("</script>", from) - from));
  const auto& fig = doc["sections"][0]["figures"][0];
  EXPECT_TRUE(fig["box"].get<bool>());
  EXPECT_EQ(fig["series"][0]["name"], "auto");
  EXPECT_DOUBLE_EQ(fig["series"][0]["box"]["median"].get<double>(), 21.5);
  EXPECT_EQ(fig["series"][0]["box"]["outliers"], nlohmann::json::array({60.0}));
  EXPECT_EQ(fig["series"][1]["box"]["n"].get<int>(), 2);
  const CsvTable t = read_csv(dir / "fig-01-cycle-time-by-mode.csv");
  EXPECT_EQ(t.column("series"), (std::vector<double>{1, 1, 1, 1, 2, 2}));
  EXPECT_EQ(t.column("cycle_time_s"), (std::vector<double>{20, 21, 22, 60, 50, 55}));
  // A box on a log axis is not drawn by the page: refused before anything is written.
  Figure log = box_figure("Log", "", "Mode", {"Force", "N", true}, {{"a", {1.0}}});
  Report bad("bad");
  bad.add_figure(log);
  try {
    bad.write(dir / "bad");
    FAIL() << "a log box plot was written";
  } catch (const InvalidParams& e) {
    EXPECT_THAT(e.what(), HasSubstr("box plot"));
  }
}

}  // namespace
}  // namespace mc::report
