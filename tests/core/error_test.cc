#include "microcobot/core/error.h"

#include <gtest/gtest.h>
#include <cmath>
#include <limits>

namespace mc {
namespace {

TEST(Error, MessagesAreOneLineAndCarryTheExitCode) {
  const InvalidParams p("pe.mass_kg", "must be finite and > 0", -1.0);
  EXPECT_STREQ(p.what(), "invalid parameter pe.mass_kg: must be finite and > 0 (got -1)");
  EXPECT_EQ(p.exit_code(), ExitCode::kInvalidInput);
  const InvalidInput i("run.csv", 12, "column 'x_m': 'abc' is not a number");
  EXPECT_STREQ(i.what(), "run.csv:12: column 'x_m': 'abc' is not a number");
  EXPECT_EQ(InvalidInput("run.csv", 0, "empty").what(), std::string("run.csv: empty"));
  EXPECT_EQ(ComputationFailed("diverged").exit_code(), ExitCode::kComputationFailed);
  EXPECT_EQ(UsageError("bad flag").exit_code(), ExitCode::kUsage);
}

TEST(Error, RequireHelpersRejectNonFiniteAndOutOfRange) {
  EXPECT_NO_THROW(require_positive(1e-12, "x"));
  EXPECT_THROW(require_positive(0.0, "x"), InvalidParams);
  EXPECT_THROW(require_positive(std::nan(""), "x"), InvalidParams);
  EXPECT_THROW(require_non_negative(-1e-300, "x"), InvalidParams);
  EXPECT_NO_THROW(require_in_range(100.0, 0.0, 100.0, "u_V"));
  EXPECT_THROW(require_in_range(100.5, 0.0, 100.0, "u_V"), InvalidParams);
  EXPECT_THROW(require_in_range(std::numeric_limits<double>::infinity(), 0.0, 100.0, "u_V"), InvalidParams);
}

}  // namespace
}  // namespace mc
