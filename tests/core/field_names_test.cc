// Errors that blame what the user typed: a library field renamed to the flag that set it, as a
// whole word or the head of a dotted path only, and the exit code kept.
#include "microcobot/core/field_names.h"

#include <gtest/gtest.h>

#include "microcobot/core/error.h"

namespace mc {
namespace {

std::string renamed(const std::string& field, const std::string& why) {
  try {
    naming_fields({{"seed", "--seed"}, {"lead_m", "--lead"}}, [&] { throw InvalidParams(field, why); });
  } catch (const InvalidParams&) {
    ADD_FAILURE() << "still an InvalidParams";
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), ExitCode::kInvalidInput);
    return e.what();
  }
  ADD_FAILURE() << "nothing thrown";
  return "";
}

TEST(FieldNames, AFieldIsRenamedAsAWholeWordOrTheHeadOfAPath) {
  EXPECT_EQ(renamed("seed", "must be >= 0"), "invalid parameter --seed: must be >= 0");
  EXPECT_NE(renamed("lead_m.x", "must be finite").find("--lead.x"), std::string::npos);
  // Not inside another name: "world.seed_offset" and "tracking.lead_m" stay as they are.
  EXPECT_NE(renamed("world.seed_offset", "must be >= 0").find("world.seed_offset"), std::string::npos);
  EXPECT_NE(renamed("tracking.lead_m", "must be >= 0").find("tracking.lead_m"), std::string::npos);
}

TEST(FieldNames, OtherErrorsPassUnchanged) {
  EXPECT_THROW(naming_fields({{"seed", "--seed"}}, [] { throw UsageError("seed"); }), UsageError);
  EXPECT_NO_THROW(naming_fields({{"seed", "--seed"}}, [] {}));
}

}  // namespace
}  // namespace mc
