#pragma once
/// @file
/// The error types of microcobot. Each carries the CLI exit code it maps to (docs/architecture.md,
/// errors): 2 usage, 3 invalid input or parameters, 4 computation failed. Messages are one
/// line and name where the problem is (file and line, or parameter field).

#include <cstddef>
#include <stdexcept>
#include <string>

namespace mc {

/// Process exit codes of the `microcobot` command line.
enum class ExitCode : int {
  kOk = 0,
  kUsage = 2,
  kInvalidInput = 3,
  kComputationFailed = 4,
};

/// Base of all microcobot errors: a one-line message and the exit code it maps to.
class Error : public std::runtime_error {
 public:
  Error(ExitCode code, const std::string& message);
  ExitCode exit_code() const { return code_; }

 private:
  ExitCode code_;
};

/// A command-line usage error (unknown flag, missing argument, bad flag value). Exit 2.
class UsageError : public Error {
 public:
  explicit UsageError(const std::string& message);
};

/// A parameter violates its constraint. The message reads "invalid parameter <field>: <constraint>
/// (got <value>)", e.g. "invalid parameter pe.mass_kg: must be > 0 (got -1)". Exit 3.
class InvalidParams : public Error {
 public:
  InvalidParams(const std::string& field, const std::string& constraint);
  InvalidParams(const std::string& field, const std::string& constraint, double got);
  const std::string& field() const { return field_; }
  /// The same error with its field under `prefix`: a section's own parameters validated inside
  /// a larger one ("lost_below" under "tracker" reads "tracker.lost_below").
  InvalidParams nested_in(const std::string& prefix) const;

 private:
  std::string field_;
};

/// Bad input data: a file that cannot be read or parsed. The message reads
/// "<file>:<line>: <what>" (line omitted when 0). Exit 3.
class InvalidInput : public Error {
 public:
  InvalidInput(const std::string& file, std::size_t line, const std::string& what);
  explicit InvalidInput(const std::string& what);
  const std::string& file() const { return file_; }
  std::size_t line() const { return line_; }

 private:
  std::string file_;
  std::size_t line_ = 0;
};

/// A computation could not produce a valid result (divergence, NaN, no convergence). Exit 4.
class ComputationFailed : public Error {
 public:
  explicit ComputationFailed(const std::string& what);
};

/// Throws InvalidParams(field, constraint, value) unless `ok`. For Params::validate().
void require(bool ok, const std::string& field, const std::string& constraint, double value);
/// Throws InvalidParams(field, constraint) unless `ok`.
void require(bool ok, const std::string& field, const std::string& constraint);

/// Work budgets, checked before a run starts (docs/cli.md, "Limits"): the simulated steps of
/// one command and the samples it keeps in memory.
inline constexpr double kMaxSimulatedSteps = 5e7;
inline constexpr double kMaxRecordedSamples = 2e7;
/// Throws InvalidParams(field) unless `amount` (steps, samples) is finite and <= `limit`;
/// `what` says what is counted, e.g. "simulated steps (duration / dt)".
void require_budget(double amount, double limit, const std::string& field, const std::string& what);

/// Throws InvalidParams unless value is finite and > 0.
void require_positive(double value, const std::string& field);
/// Throws InvalidParams unless value is finite and >= 0.
void require_non_negative(double value, const std::string& field);
/// Throws InvalidParams unless value is finite and lo <= value <= hi.
void require_in_range(double value, double lo, double hi, const std::string& field);

}  // namespace mc
