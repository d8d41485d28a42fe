// The command line as a user meets it: help, version, exit codes and one-line errors.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/test_support.h"

namespace mc {
namespace {

using ::testing::HasSubstr;
using test::line_count;
using test::run_cli;

TEST(Cli, HelpListsTheCommandGroups) {
  const auto r = run_cli({"--help"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_THAT(r.out, HasSubstr("Subcommands:"));
  EXPECT_THAT(r.out, HasSubstr("report"));
}

TEST(Cli, VersionPrintsTheVersion) {
  const auto r = run_cli({"--version"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_THAT(r.out, HasSubstr("microcobot 0."));
}

TEST(Cli, UsageErrorsExitTwoWithOneLine) {
  for (const auto& args : std::vector<std::vector<std::string>>{
           {"--no-such-flag"}, {}, {"no-such-group"}, {"report", "--out"}, {"report", "--bogus"}}) {
    const auto r = run_cli(args);
    EXPECT_EQ(r.exit_code, 2) << (args.empty() ? "" : args[0]);
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
    EXPECT_THAT(r.err, HasSubstr("microcobot: error:"));
    EXPECT_EQ(r.out, "");
  }
}

TEST(Cli, ReportWritesIndexAndJsonSummary) {
  test::TempDir dir;
  const auto r = run_cli({"report", "--only", "rng", "--out", (dir / "r").string(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["index"], (dir / "r" / "index.html").string());
  EXPECT_GE(j["figures"].get<int>(), 1);
  EXPECT_TRUE(std::filesystem::exists(dir / "r" / "index.html"));
}

TEST(Cli, ReportIntoAnUnwritablePlaceExitsThree) {
  test::TempDir dir;
  test::write_text(dir / "file", "x");
  const auto r = run_cli({"report", "--only", "rng", "--out", (dir / "file" / "r").string()});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(line_count(r.err), 1u) << r.err;
  EXPECT_THAT(r.err, HasSubstr((dir / "file" / "r").string()));
}

TEST(Cli, ReportRejectsAnUnknownPart) {
  const auto r = run_cli({"report", "--only", "nonsense"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("unknown report part 'nonsense'"));
}

}  // namespace
}  // namespace mc
