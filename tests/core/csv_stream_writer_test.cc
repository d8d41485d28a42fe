#include "microcobot/core/csv_stream_writer.h"

#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "support/test_support.h"

namespace mc {
namespace {

using ::testing::HasSubstr;

// Only the file itself: no temporary file left beside it.
std::vector<std::string> files_in(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    names.push_back(e.path().filename().string());
  return names;
}

TEST(CsvStreamWriter, RowsWrittenOneByOneReadBackExactly) {
  test::TempDir dir;
  const auto file = dir / "rec.csv";
  CsvStreamWriter w(file, {"t_s", "x_m", "f_N"});
  // Enough rows to flush the buffer several times; values that need all 17 digits.
  for (int i = 0; i < 20000; ++i) {
    const double t = 1e-4 * i;
    const std::array<double, 3> row{t, std::sin(t) * 1e-6 / 3.0, -1e-300 * i / 7.0};
    w.append(row);
  }
  EXPECT_FALSE(std::filesystem::exists(file)) << "nothing under the name before close()";
  w.close();
  w.close();  // idempotent
  EXPECT_EQ(w.rows(), 20000u);
  EXPECT_EQ(files_in(dir.path()), std::vector<std::string>{"rec.csv"});
  const CsvTable t = read_csv(file);
  ASSERT_EQ(t.rows(), 20000u);
  EXPECT_EQ(t.names(), (std::vector<std::string>{"t_s", "x_m", "f_N"}));
  for (int i : {0, 1, 9999, 19999}) {
    const double ti = 1e-4 * i;
    EXPECT_EQ(t.column("t_s")[static_cast<std::size_t>(i)], ti);
    EXPECT_EQ(t.column("x_m")[static_cast<std::size_t>(i)], std::sin(ti) * 1e-6 / 3.0);
    EXPECT_EQ(t.column("f_N")[static_cast<std::size_t>(i)], -1e-300 * i / 7.0);
  }
}

TEST(CsvStreamWriter, AnAbandonedOrFailedFileLeavesNothing) {
  test::TempDir dir;
  {
    CsvStreamWriter w(dir / "cut.csv", {"t_s"});
    w.append(std::array<double, 1>{1.0});
  }  // destroyed without close(): a cut recording
  EXPECT_TRUE(files_in(dir.path()).empty());

  CsvStreamWriter nan(dir / "nan.csv", {"t_s", "x_m"});
  nan.append(std::array<double, 2>{0.0, 1.0});
  try {
    nan.append(std::array<double, 2>{1.0, std::numeric_limits<double>::quiet_NaN()});
    FAIL() << "a NaN is refused (the reader refuses it too)";
  } catch (const InvalidInput& e) {
    EXPECT_THAT(e.what(), HasSubstr("nan.csv"));
    EXPECT_THAT(e.what(), HasSubstr("non-finite value in column 2 of row 2"));
  }
  EXPECT_THROW(nan.append(std::array<double, 2>{2.0, 2.0}), InvalidInput) << "abandoned";
  EXPECT_TRUE(files_in(dir.path()).empty());

  CsvStreamWriter ragged(dir / "ragged.csv", {"t_s", "x_m"});
  EXPECT_THROW(ragged.append(std::array<double, 1>{0.0}), InvalidInput);
  EXPECT_TRUE(files_in(dir.path()).empty());
}

TEST(CsvStreamWriter, RefusesBadNamesAndAMissingDirectory) {
  test::TempDir dir;
  EXPECT_THROW(CsvStreamWriter(dir / "a.csv", {}), InvalidInput);
  EXPECT_THROW(CsvStreamWriter(dir / "a.csv", {"t_s", "x,m"}), InvalidInput);
  EXPECT_THROW(CsvStreamWriter(dir / "a.csv", {""}), InvalidInput);
  try {
    CsvStreamWriter w(dir / "missing" / "a.csv", {"t_s"});
    FAIL();
  } catch (const InvalidInput& e) {
    EXPECT_THAT(e.what(), HasSubstr("missing/a.csv"));
  }
  EXPECT_TRUE(files_in(dir.path()).empty());
}

}  // namespace
}  // namespace mc
