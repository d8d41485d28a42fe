#include "microcobot/core/mat_file.h"

#include <cmath>
#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "support/test_support.h"

namespace mc {
namespace {

using ::testing::HasSubstr;

/// The message of the InvalidInput that `f` throws (fails the test when it throws nothing).
template <class F>
std::string invalid_input(F&& f) {
  try {
    f();
  } catch (const InvalidInput& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InvalidInput";
  return {};
}

TEST(MatFile, RoundTripKeepsShapesAndValues) {
  test::TempDir dir;
  const auto f = dir / "a.mat";
  MatArray m{"m", 2, 3, {1, 2, 3, 4, 5, 6}};  // column-major
  write_mat(f, {MatArray::column("t_s", {0.0, 1e-5, 2e-5}), m, MatArray::scalar("g", -9.81)});
  const auto vars = read_mat(f);
  ASSERT_EQ(vars.size(), 3u);
  EXPECT_EQ(vars[0].name, "t_s");
  EXPECT_EQ(vars[0].rows, 3u);
  EXPECT_EQ(vars[0].cols, 1u);
  EXPECT_EQ(vars[0].data, (std::vector<double>{0.0, 1e-5, 2e-5}));
  EXPECT_EQ(vars[1].rows, 2u);
  EXPECT_EQ(vars[1].cols, 3u);
  EXPECT_EQ(vars[1].data, m.data);
  EXPECT_EQ(vars[2].data, std::vector<double>{-9.81});
  // No temporary file is left beside it.
  EXPECT_EQ(
      std::distance(std::filesystem::directory_iterator(dir.path()), std::filesystem::directory_iterator()),
      1);
}

TEST(MatFile, ColumnsAsATable) {
  test::TempDir dir;
  const auto f = dir / "r.mat";
  write_mat(f, {MatArray::column("t", {0, 1, 2}), MatArray{"u", 1, 3, {4, 5, 6}},
                MatArray::column("x", {7, 8, 9})});
  const auto t = read_mat_columns(f, {"t", "u", "x"}, {"t_s", "u_V", "x_m"});
  EXPECT_EQ(t.names(), (std::vector<std::string>{"t_s", "u_V", "x_m"}));
  EXPECT_EQ(t.column("u_V"), (std::vector<double>{4, 5, 6}));  // a row vector is a vector too
  EXPECT_EQ(read_columns(f, {"x"}).column("x"), (std::vector<double>{7, 8, 9}));
}

TEST(MatFile, BadFilesGiveOneLineErrorsNamingFileAndVariable) {
  test::TempDir dir;
  const auto f = dir / "bad.mat";
  const double nan = std::numeric_limits<double>::quiet_NaN();
  write_mat(f, {MatArray::column("t", {0, 1, 2}), MatArray{"u", 2, 2, {1, 2, 3, 4}},
                MatArray::column("x", {0, nan, 1}), MatArray::column("y", {1, 2})});
  const std::string p = f.string();
  EXPECT_EQ(invalid_input([&] {
              read_mat_columns(f, {"t", "z"});
            }),
            p + ": variable 'z': missing (have: t, u, x, y)");
  EXPECT_EQ(invalid_input([&] { read_mat_columns(f, {"u"}); }),
            p + ": variable 'u': expected a vector (1xN or Nx1), got 2x2");
  EXPECT_EQ(invalid_input([&] { read_mat_columns(f, {"x"}); }),
            p + ": variable 'x': non-finite value nan at index 1");
  EXPECT_EQ(invalid_input([&] {
              read_mat_columns(f, {"t", "y"});
            }),
            p + ": variable 'y': length 2, expected 3 (as 't')");
  test::write_text(dir / "text.mat", "t,u,x\n");
  EXPECT_THAT(invalid_input([&] { read_mat(dir / "text.mat"); }), HasSubstr("not a MATLAB .mat file"));
  EXPECT_THAT(invalid_input([&] { read_mat(dir / "none.mat"); }), HasSubstr("none.mat: no such file"));
  EXPECT_THAT(invalid_input([&] { read_mat(dir.path()); }), HasSubstr("not a regular file"));
}

TEST(MatFile, WriteRefusesBadNamesAndShapesWithoutLeavingAFile) {
  test::TempDir dir;
  const auto f = dir / "w.mat";
  EXPECT_THAT(invalid_input([&] { write_mat(f, {MatArray::column("1x", {1})}); }),
              HasSubstr("'1x' is not a MATLAB identifier"));
  EXPECT_THAT(invalid_input([&] {
                write_mat(f, {MatArray::column("a", {1}), MatArray::column("a", {2})});
              }),
              HasSubstr("'a' written twice"));
  EXPECT_THAT(invalid_input([&] {
                write_mat(f, {MatArray{"m", 2, 2, {1, 2, 3}}});
              }),
              HasSubstr("3 values for a 2x2 array"));
  EXPECT_FALSE(std::filesystem::exists(f));
}

}  // namespace
}  // namespace mc
