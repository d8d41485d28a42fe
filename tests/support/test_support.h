#pragma once
/// @file
/// Helpers for tests: run the CLI as a user would, scratch directories, waiting for conditions.

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

namespace mc::test {

struct CliResult {
  int exit_code = -1;
  std::string out;  ///< stdout
  std::string err;  ///< stderr
};

/// Runs the built `microcobot` binary with `args` (no shell), capturing stdout and stderr.
CliResult run_cli(const std::vector<std::string>& args);

/// Starts `argv` (argv[0] the program's path; no shell) in the background, stdin from /dev/null,
/// stdout and stderr into the files `out` and `err`; returns its pid (throws when it cannot start).
pid_t spawn_process(const std::vector<std::string>& argv, const std::filesystem::path& out,
                    const std::filesystem::path& err);

/// Waits up to `timeout` for the child `pid`: its exit code, 128 + signal when a signal ended it,
/// -1 when it was still running (then it is killed with SIGKILL and reaped).
int wait_process(pid_t pid, std::chrono::milliseconds timeout);

/// The `microcobot` binary in the background (a server, a DDS peer): stdout and stderr go to
/// `<prefix>.out` and `<prefix>.err`.
struct BackgroundCli {
  pid_t pid = 0;
  std::filesystem::path out, err;
};
BackgroundCli spawn_cli(const std::vector<std::string>& args, const std::filesystem::path& prefix);

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

/// Polls `condition` every 10 ms until it holds or `timeout` passes; returns whether it held.
/// Tests of threads and wall-clock loops wait for what they assert rather than for a fixed time,
/// so that a sanitized build on a loaded machine is slower, not failed.
template <class Condition>
bool eventually(Condition&& condition, std::chrono::milliseconds timeout = std::chrono::seconds(20)) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (!condition()) {
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

}  // namespace mc::test
