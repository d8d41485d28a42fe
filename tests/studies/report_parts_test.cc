// The full report's parts as the library lists them: every module's part once, in the
// architecture's order, each built without the command line.

#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "microcobot/report/report.h"
#include "microcobot/studies/report_parts.h"

namespace mc::studies {
namespace {

TEST(ReportParts, EveryModulesPartIsListedOnceInTheArchitecturesOrder) {
  const std::vector<ReportPart> parts = report_parts();
  std::vector<std::string> names;
  for (const ReportPart& p : parts) names.push_back(p.name);
  EXPECT_EQ(names, (std::vector<std::string>{"rng", "dsp", "stickslip", "identify", "haptics", "control",
                                             "positioner", "tweezers"}));
  for (std::size_t i = 1; i < parts.size(); ++i) EXPECT_LT(parts[i - 1].order, parts[i].order) << names[i];
  for (const ReportPart& p : parts) EXPECT_TRUE(p.build) << p.name;
}

TEST(ReportParts, APartBuildsItsFiguresIntoAReport) {
  for (const ReportPart& p : report_parts()) {
    if (p.name != "rng" && p.name != "dsp") continue;  // the quick ones; `report` builds them all
    report::Report r(p.name);
    p.build(r);
    EXPECT_GE(r.figure_count(), 1u) << p.name;
  }
}

}  // namespace
}  // namespace mc::studies
