#include "microcobot/core/csv.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "support/test_support.h"

namespace mc {
namespace {

using ::testing::HasSubstr;

TEST(Csv, ParsesHeaderCommentsAndNumbers) {
  const auto t = parse_csv("# measured 2024\nt_s, u_V ,x_m\n0,1.5,-2e-9\n\n# mid comment\n1e-3,+2,3\n", "m.csv");
  ASSERT_EQ(t.cols(), 3u);
  ASSERT_EQ(t.rows(), 2u);
  EXPECT_EQ(t.names()[1], "u_V");
  EXPECT_DOUBLE_EQ(t.column("x_m")[0], -2e-9);
  EXPECT_DOUBLE_EQ(t.column("u_V")[1], 2.0);
  EXPECT_DOUBLE_EQ(t.column("t_s")[1], 1e-3);
}

struct BadCase {
  std::string text;
  std::string message;
  std::size_t line;
};

TEST(Csv, BadInputIsRejectedWithFileAndLine) {
  const std::vector<BadCase> cases = {
      {"t_s,x_m\n0,1\n1,abc\n", "m.csv:3: column 'x_m': 'abc' is not a number", 3},
      {"t_s,x_m\n0,nan\n", "m.csv:2: column 'x_m': non-finite value 'nan'", 2},
      {"t_s,x_m\n0,inf\n", "non-finite value 'inf'", 2},
      {"t_s,x_m\n0,1\n1,2,3\n", "m.csv:3: row has 3 cells, header has 2", 3},
      {"t_s,x_m\n0,\n", "m.csv:2: column 'x_m': '' is not a number", 2},
      {"", "m.csv: empty file (no header row)", 0},
      {"# only a comment\n", "empty file", 0},
      {"t_s,x_m\n", "m.csv: no data rows", 0},
      {"t_s,t_s\n1,2\n", "m.csv:1: duplicate column 't_s'", 1},
      {"t_s,,x\n1,2,3\n", "empty column name", 1},
      {"t_s\n1.5.2\n", "'1.5.2' is not a number", 2},
  };
  for (const auto& c : cases) {
    try {
      parse_csv(c.text, "m.csv");
      ADD_FAILURE() << "accepted: " << c.text;
    } catch (const InvalidInput& e) {
      EXPECT_THAT(e.what(), HasSubstr(c.message)) << c.text;
      EXPECT_EQ(e.line(), c.line) << c.text;
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
  }
}

TEST(Csv, MissingColumnNamesTheFileAndTheColumnsItHas) {
  const auto t = parse_csv("t_s,u_V\n0,1\n", "run.csv");
  try {
    t.column("x_m");
    FAIL();
  } catch (const InvalidInput& e) {
    EXPECT_THAT(e.what(), HasSubstr("run.csv: missing column 'x_m' (have: t_s,u_V)"));
  }
}

TEST(Csv, WriteThenReadRoundTripsExactly) {
  test::TempDir dir;
  CsvTable t;
  t.add_column("t_s", {0.0, 1e-6, 0.1 + 0.2});
  t.add_column("x_m", {1.0 / 3.0, -2.5e-12, 6.02214076e23});
  write_csv(dir / "a.csv", t, {"made by a test"});
  const auto back = read_csv(dir / "a.csv");
  EXPECT_EQ(back.names(), t.names());
  for (std::size_t c = 0; c < 2; ++c) EXPECT_EQ(back.column(c), t.column(c));
  EXPECT_THAT(test::read_text(dir / "a.csv"), ::testing::StartsWith("# made by a test\nt_s,x_m\n"));
}

TEST(Csv, WritingNonFiniteFailsAndLeavesThePreviousFile) {
  test::TempDir dir;
  CsvTable good;
  good.add_column("x_m", {1.0});
  write_csv(dir / "a.csv", good);
  CsvTable bad;
  bad.add_column("x_m", {1.0, std::nan("")});
  EXPECT_THROW(write_csv(dir / "a.csv", bad), ComputationFailed);
  EXPECT_EQ(test::read_text(dir / "a.csv"), "x_m\n1\n");
  // Nothing half-written is left behind.
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path())) ++files;
  EXPECT_EQ(files, 1u);
}

TEST(Csv, UnwritableDirectoryIsInvalidInput) {
  test::TempDir dir;
  CsvTable t;
  t.add_column("x_m", {1.0});
  EXPECT_THROW(write_csv(dir / "missing" / "a.csv", t), InvalidInput);
  if (::geteuid() != 0) {  // root ignores permissions
    ::chmod(dir.path().c_str(), 0500);
    EXPECT_THROW(write_csv(dir / "a.csv", t), InvalidInput);
    ::chmod(dir.path().c_str(), 0700);
  }
  test::write_text(dir / "file", "x");
  EXPECT_THROW(ensure_writable_dir(dir / "file" / "sub"), InvalidInput);
}

TEST(Csv, MissingFileIsInvalidInput) {
  try {
    read_csv("/nonexistent/run.csv");
    FAIL();
  } catch (const InvalidInput& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent/run.csv: cannot open file"));
  }
}

}  // namespace
}  // namespace mc
