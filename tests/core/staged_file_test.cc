#include "microcobot/core/staged_file.h"

#include <sys/stat.h>

#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "support/test_support.h"

namespace mc {
// The file's own namespace: its helpers keep their names beside the other test files of the
// module in a unity build (MC_UNITY_TESTS).
namespace staged_file_test {
namespace {

using ::testing::HasSubstr;

std::size_t entries(const std::filesystem::path& dir) {
  std::size_t n = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) n += e.exists() ? 1 : 0;
  return n;
}

TEST(StagedFile, AppearsUnderItsNameOnlyWhenCommittedReadableByAll) {
  test::TempDir dir;
  StagedFile f(dir / "out.txt");
  f.write("hello, ");
  f.write("world\n");
  EXPECT_FALSE(std::filesystem::exists(dir / "out.txt"));
  EXPECT_EQ(entries(dir.path()), 1u) << "the temporary beside it";
  f.commit();
  f.commit();  // idempotent
  EXPECT_TRUE(f.committed());
  EXPECT_EQ(test::read_text(dir / "out.txt"), "hello, world\n");
  EXPECT_EQ(entries(dir.path()), 1u) << "no temporary left";
  struct stat st {};
  ASSERT_EQ(::stat((dir / "out.txt").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0644u);
  try {
    f.write("more");
    FAIL() << "written after commit";
  } catch (const InvalidInput& e) {
    EXPECT_THAT(e.what(), HasSubstr("out.txt"));
  }
}

TEST(StagedFile, AnAbandonedFileLeavesNothingAndAnExistingFileIsKept) {
  test::TempDir dir;
  test::write_text(dir / "keep.txt", "the previous version\n");
  {
    StagedFile f(dir / "keep.txt");
    f.write("half a new vers");
  }  // an exception unwinding, a cut run
  EXPECT_EQ(test::read_text(dir / "keep.txt"), "the previous version\n");
  StagedFile g(dir / "gone.txt");
  g.write("x");
  g.discard();
  EXPECT_THROW(g.write("y"), InvalidInput);
  EXPECT_THROW(g.commit(), InvalidInput);
  EXPECT_EQ(entries(dir.path()), 1u);
  EXPECT_THROW(StagedFile(dir / "missing" / "a.txt"), InvalidInput);
}

}  // namespace
}  // namespace staged_file_test
}  // namespace mc
