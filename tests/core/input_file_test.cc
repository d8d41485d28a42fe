// Reading input files (regular files only, size caps) and one-line message helpers.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/stat.h>

#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "support/test_support.h"

namespace mc {
namespace {

using ::testing::HasSubstr;

TEST(InputFile, RefusesWhatIsNotARegularFile) {
  test::TempDir d;
  std::filesystem::create_directory(d / "dir");
  ASSERT_EQ(::mkfifo((d / "fifo").c_str(), 0600), 0);
  for (const auto& [path, what] :
       std::vector<std::pair<std::string, std::string>>{{(d / "dir").string(), "directory"},
                                                        {(d / "fifo").string(), "FIFO"},
                                                        {"/dev/zero", "device"},
                                                        {(d / "missing").string(), "cannot open"}}) {
    try {
      read_input_file(path, 1024, "test file");
      ADD_FAILURE() << path;
    } catch (const InvalidInput& e) {
      EXPECT_THAT(e.what(), HasSubstr(what));
      EXPECT_THAT(e.what(), HasSubstr(path));
    }
  }
}

TEST(InputFile, RefusesFilesBeyondTheCap) {
  test::TempDir d;
  test::write_text(d / "f", std::string(2000, 'x'));
  EXPECT_EQ(read_input_file(d / "f", 2000, "test file").size(), 2000u);
  EXPECT_THROW(read_input_file(d / "f", 1999, "test file"), InvalidInput);
}

TEST(InputFile, ExcerptCutsThePrintedForm) {
  EXPECT_EQ(excerpt("abc"), "abc");
  EXPECT_EQ(excerpt("a\nb\x01"), "a\\nb\\x01");
  const std::string binary(1000, '\xff');
  EXPECT_LE(excerpt(binary).size(), 83u);
  EXPECT_EQ(fmt_number(1.7976931348623157e308), "1.79769e+308");
  EXPECT_EQ(fmt_number(1e-10), "1e-10");
}

// Found by the CSV fuzzer: binary header and cells made a 423-character message.
TEST(InputFile, CsvMessagesStayShortForBinaryInput) {
  const std::string header(17, '\xdd'), cell(100, '\xff');
  try {
    parse_csv(header + "\r" + cell + "\n", "fuzz.csv");
    ADD_FAILURE();
  } catch (const InvalidInput& e) {
    EXPECT_LE(std::string(e.what()).size(), 260u) << e.what();
  }
}

}  // namespace
}  // namespace mc
