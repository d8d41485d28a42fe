#pragma once
/// @file
/// A file written under a temporary name beside its target (`.NAME.XXXXXX`) and renamed into
/// place by commit(), so that a reader never sees it half-written and one that is abandoned (a
/// failed write, an exception unwinding, a cut run) leaves nothing. The streaming writers (MCAP,
/// CSV) and write_file_atomic are built on it.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace mc {

/// Why `path` (a file or directory to create) could not be created, given the errno of the
/// failed call: "its name is 300 characters long (the limit is 255)", "directory missing",
/// "directory not writable", else strerror. For one-line errors that name what the user gave.
std::string why_not_created(const std::filesystem::path& path, int err);

/// Whether the temporary file `tmp` is held by a StagedFile still open in some process: each
/// holds an advisory lock (flock) on its temporary, which the kernel releases when the process
/// dies. A temporary that is not held was left by a writer that crashed.
bool staged_file_in_use(const std::filesystem::path& tmp);

class StagedFile {
 public:
  /// Creates the temporary file. Throws InvalidInput naming `path` when the directory is
  /// missing or not writable.
  explicit StagedFile(std::filesystem::path path);
  /// Without commit(): the temporary file is removed.
  ~StagedFile();
  StagedFile(const StagedFile&) = delete;
  StagedFile& operator=(const StagedFile&) = delete;

  /// Writes all of `bytes`. On failure (disk full) the file is discarded and InvalidInput
  /// naming `path` is thrown; so is writing to a file committed or discarded.
  void write(std::string_view bytes);
  /// From now on a failed write or commit keeps the temporary instead: cut back to what was
  /// written before the failed call, still open (the owner may truncate() it and write again),
  /// and left in place when destroyed after a failure (a writer of whole records leaves a file
  /// whose records can be recovered: core/mcap_recover.h).
  void keep_on_failure() noexcept { keep_on_failure_ = true; }
  /// Cuts the file to its first `size` bytes and writes on from there. Throws InvalidInput.
  void truncate(std::uint64_t size);
  /// Bytes written so far.
  std::uint64_t size() const { return size_; }
  /// Syncs, makes the file readable by all (0644, as any output) and renames it to `path`.
  /// Throws InvalidInput (the file discarded) when any of that fails. Idempotent.
  void commit();
  /// Removes the temporary file now. Never throws; idempotent.
  void discard() noexcept;

  const std::filesystem::path& path() const { return path_; }
  bool committed() const { return committed_; }

 private:
  [[noreturn]] void fail(const std::string& what);

  std::filesystem::path path_;
  std::string tmp_path_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
  bool committed_ = false;
  bool keep_on_failure_ = false;
  bool failed_ = false;
};

}  // namespace mc
