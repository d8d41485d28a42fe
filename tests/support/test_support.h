#pragma once
/// @file
/// Helpers for tests: run the CLI as a user would, and scratch directories.

#include <filesystem>
#include <string>
#include <vector>

namespace mc::test {

struct CliResult {
  int exit_code = -1;
  std::string out;  ///< stdout
  std::string err;  ///< stderr
};

/// Runs the built `microcobot` binary with `args` (no shell), capturing stdout and stderr.
CliResult run_cli(const std::vector<std::string>& args);

/// A fresh empty directory under the system temp dir, removed on destruction.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

/// Writes `text` to `file` (test fixtures).
void write_text(const std::filesystem::path& file, const std::string& text);
/// Reads a whole file.
std::string read_text(const std::filesystem::path& file);
/// Number of lines in `s` (a trailing newline does not start a new line).
std::size_t line_count(const std::string& s);

}  // namespace mc::test
