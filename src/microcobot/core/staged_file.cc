#include "microcobot/core/staged_file.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <system_error>

#include "microcobot/core/error.h"

namespace mc {

std::string why_not_created(const std::filesystem::path& path, int err) {
  const std::size_t name = path.filename().string().size();
  if (name > NAME_MAX) {
    return "its name is " + std::to_string(name) + " characters long (the limit is " +
           std::to_string(NAME_MAX) + ")";
  }
  if (err == ENOENT || err == ENOTDIR) return "directory missing";
  if (err == EACCES || err == EPERM || err == EROFS) return "directory not writable";
  return std::strerror(err);
}

namespace {
// "disk full" for ENOSPC and EDQUOT (and EFBIG: the file size limit), else strerror.
std::string why_write_failed(int err) {
  if (err == ENOSPC || err == EDQUOT || err == EFBIG)
    return "write failed: disk full (" + std::string(std::strerror(err)) + ")";
  return "write failed: " + std::string(std::strerror(err));
}
}  // namespace

StagedFile::StagedFile(std::filesystem::path path) : path_(std::move(path)) {
  if (path_.filename().string().size() > NAME_MAX)
    throw InvalidInput(path_.string(), 0, "cannot write: " + why_not_created(path_, ENAMETOOLONG));
  const std::filesystem::path dir = path_.has_parent_path() ? path_.parent_path() : ".";
  // The temporary's name holds at most 64 bytes of the target's: a name near the file system's
  // limit (255) is a valid target, and its temporary must be creatable too.
  tmp_path_ = (dir / ("." + path_.filename().string().substr(0, 64) + ".XXXXXX")).string();
  fd_ = ::mkstemp(tmp_path_.data());
  if (fd_ < 0) {
    const int err = errno;
    tmp_path_.clear();
    throw InvalidInput(path_.string(), 0, "cannot write: " + why_not_created(path_, err));
  }
  // Held until the file is closed, released by the kernel when the process dies: a temporary
  // found unlocked was left by a writer that crashed (staged_file_in_use).
  ::flock(fd_, LOCK_EX | LOCK_NB);
}

bool staged_file_in_use(const std::filesystem::path& tmp) {
  const int fd = ::open(tmp.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool locked = ::flock(fd, LOCK_EX | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  ::close(fd);  // releases the lock this call may have taken
  return locked;
}

StagedFile::~StagedFile() {
  if (keep_on_failure_ && failed_) {
    if (fd_ >= 0) ::close(fd_);  // the temporary stays, for a recovery
    return;
  }
  discard();
}

void StagedFile::discard() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  if (!tmp_path_.empty()) ::unlink(tmp_path_.c_str());
  tmp_path_.clear();
}

void StagedFile::fail(const std::string& what) {
  if (keep_on_failure_ && !tmp_path_.empty()) {
    failed_ = true;
    // What the failed call wrote in part goes: the file ends where the last whole call did.
    if (fd_ >= 0 && ::ftruncate(fd_, static_cast<off_t>(size_)) == 0)
      ::lseek(fd_, static_cast<off_t>(size_), SEEK_SET);
    throw InvalidInput(path_.string(), 0, what);
  }
  discard();
  throw InvalidInput(path_.string(), 0, what);
}

void StagedFile::truncate(std::uint64_t size) {
  if (fd_ < 0)
    throw InvalidInput(path_.string(), 0, committed_ ? "truncated after it was closed" : "abandoned");
  if (::ftruncate(fd_, static_cast<off_t>(size)) != 0 ||
      ::lseek(fd_, static_cast<off_t>(size), SEEK_SET) != static_cast<off_t>(size))
    fail(std::string("cannot cut the file: ") + std::strerror(errno));
  size_ = size;
}

void StagedFile::write(std::string_view bytes) {
  if (fd_ < 0)
    throw InvalidInput(path_.string(), 0, committed_ ? "written after it was closed" : "abandoned");
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail(why_write_failed(n < 0 ? errno : ENOSPC));
    done += static_cast<std::size_t>(n);
  }
  size_ += bytes.size();
}

void StagedFile::commit() {
  if (committed_) return;
  if (fd_ < 0) throw InvalidInput(path_.string(), 0, "abandoned");
  if (::fsync(fd_) != 0) fail(why_write_failed(errno));  // a full disk may show only here
  bool ok = ::close(fd_) == 0;
  fd_ = -1;
  // mkstemp creates 0600; output files are meant to be shared like any other.
  ok = ok && ::chmod(tmp_path_.c_str(), 0644) == 0;
  std::error_code ec;
  if (ok) std::filesystem::rename(tmp_path_, path_, ec);
  if (!ok || ec) fail("write failed (disk full or not writable)");
  tmp_path_.clear();
  committed_ = true;
}

}  // namespace mc
