#include "microcobot/core/error.h"

#include <cmath>

#include <fmt/format.h>

namespace mc {

Error::Error(ExitCode code, const std::string& message) : std::runtime_error(message), code_(code) {}

UsageError::UsageError(const std::string& message) : Error(ExitCode::kUsage, message) {}

InvalidParams::InvalidParams(const std::string& field, const std::string& constraint)
    : Error(ExitCode::kInvalidInput, fmt::format("invalid parameter {}: {}", field, constraint)),
      field_(field) {}

InvalidParams::InvalidParams(const std::string& field, const std::string& constraint, double got)
    : Error(ExitCode::kInvalidInput,
            fmt::format("invalid parameter {}: {} (got {:g})", field, constraint, got)),
      field_(field) {}

InvalidParams InvalidParams::nested_in(const std::string& prefix) const {
  const std::string what = this->what(), head = fmt::format("invalid parameter {}: ", field_);
  const std::string rest = what.rfind(head, 0) == 0 ? what.substr(head.size()) : what;
  return InvalidParams(prefix + "." + field_, rest);
}

namespace {
std::string located(const std::string& file, std::size_t line, const std::string& what) {
  if (file.empty()) return what;
  if (line == 0) return fmt::format("{}: {}", file, what);
  return fmt::format("{}:{}: {}", file, line, what);
}
}  // namespace

InvalidInput::InvalidInput(const std::string& file, std::size_t line, const std::string& what)
    : Error(ExitCode::kInvalidInput, located(file, line, what)), file_(file), line_(line) {}

InvalidInput::InvalidInput(const std::string& what) : Error(ExitCode::kInvalidInput, what) {}

ComputationFailed::ComputationFailed(const std::string& what) : Error(ExitCode::kComputationFailed, what) {}

void require(bool ok, const std::string& field, const std::string& constraint, double value) {
  if (!ok) throw InvalidParams(field, constraint, value);
}

void require(bool ok, const std::string& field, const std::string& constraint) {
  if (!ok) throw InvalidParams(field, constraint);
}

void require_budget(double amount, double limit, const std::string& field, const std::string& what) {
  if (std::isfinite(amount) && amount <= limit) return;
  throw InvalidParams(field, fmt::format("the run would need {:.3g} {}; the limit is {:g} (work budget, "
                                         "docs/cli.md)",
                                         amount, what, limit));
}

void require_positive(double value, const std::string& field) {
  require(std::isfinite(value) && value > 0.0, field, "must be finite and > 0", value);
}

void require_non_negative(double value, const std::string& field) {
  require(std::isfinite(value) && value >= 0.0, field, "must be finite and >= 0", value);
}

void require_in_range(double value, double lo, double hi, const std::string& field) {
  require(std::isfinite(value) && value >= lo && value <= hi, field,
          fmt::format("must be in [{:g}, {:g}]", lo, hi), value);
}

}  // namespace mc
